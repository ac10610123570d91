"""The 3D Layered Semantic Graph of 000 Sec IV: Target -> Level -> Pose -> Feature."""
