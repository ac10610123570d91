"""Perception: from sensor frames to semantic observations (detection, localisation, similarity)."""

from seminspect.perception.detections import detection_points, observe
from seminspect.perception.encoders import (
    Calibration,
    Encoder,
    TextEncoder,
    make_encoder,
    register_encoder,
)
from seminspect.perception.observation import Observation
from seminspect.perception.similarity import SceneMatcher, scene_similarity

__all__ = [
    "Calibration",
    "Encoder",
    "Observation",
    "SceneMatcher",
    "TextEncoder",
    "detection_points",
    "make_encoder",
    "observe",
    "register_encoder",
    "scene_similarity",
]
