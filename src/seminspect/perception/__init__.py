"""Perception: from sensor frames to semantic observations (detection, localisation, similarity),
and a detector of the user's own (a YOLOv8-seg model in ONNX)."""

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
from seminspect.perception.yolo_seg import ClassMap, YoloSegDetector

__all__ = [
    "Calibration",
    "ClassMap",
    "Encoder",
    "Observation",
    "SceneMatcher",
    "TextEncoder",
    "YoloSegDetector",
    "detection_points",
    "make_encoder",
    "observe",
    "register_encoder",
    "scene_similarity",
]
