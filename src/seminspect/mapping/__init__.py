"""Metric maps: voxel occupancy (free / occupied / unknown) and metric-semantic point clouds."""

from seminspect.mapping.formats.octomap import load_octomap
from seminspect.mapping.formats.pointfiles import PointData, load_point_file
from seminspect.mapping.semantic_cloud import SemanticCloud, fuse_scan, load_cloud, save_cloud
from seminspect.mapping.voxel import VoxelMap, load_map, save_map

__all__ = [
    "PointData",
    "SemanticCloud",
    "VoxelMap",
    "fuse_scan",
    "load_cloud",
    "load_map",
    "load_octomap",
    "load_point_file",
    "save_cloud",
    "save_map",
]
