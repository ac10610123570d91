"""Metric maps: voxel occupancy (free / occupied / unknown) and metric-semantic point clouds."""
