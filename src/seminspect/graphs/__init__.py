"""Scene graphs: the 3D Layered Semantic Graph (``lsg``) and outdoor task graphs (``terrain``)."""
