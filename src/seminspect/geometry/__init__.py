"""Pure geometry: poses, rotations, validation of metric inputs. No I/O, no state."""

from seminspect.geometry.nearest import NearestIndex
from seminspect.geometry.polygons import polygon_centroid, polygon_contains, ring_polygon
from seminspect.geometry.spatial_hash import PointHash
from seminspect.geometry.transforms import (
    as_point,
    as_quaternion,
    quat_from_yaw,
    wrap_angle,
    yaw_from_quat,
)

__all__ = [
    "NearestIndex",
    "PointHash",
    "as_point",
    "as_quaternion",
    "polygon_centroid",
    "polygon_contains",
    "quat_from_yaw",
    "ring_polygon",
    "wrap_angle",
    "yaw_from_quat",
]
