"""Readers and writers of the field's map and sensor files: OctoMap, ROS bags, SemanticKITTI,
point files (PLY, PCD, LAS, NPZ)."""
