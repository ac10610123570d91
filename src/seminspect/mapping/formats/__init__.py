"""Readers and writers of the field's map and sensor files: OctoMap ``.bt``, ROS bags,
SemanticKITTI scans and labels, point files (PLY, PCD, NPZ)."""

from seminspect.mapping.formats.octomap import load_octomap
from seminspect.mapping.formats.pointfiles import PointData, load_point_file

__all__ = ["PointData", "load_octomap", "load_point_file"]
