"""Perception: from sensor frames to semantic observations (detection, localisation, similarity),
a detector of the user's own (a YOLOv8-seg model in ONNX) and the learned detector trained here
(its ONNX export; training it needs torch: ``perception.training``)."""

from seminspect.perception.detections import detection_points, observe
from seminspect.perception.encoders import (
    Calibration,
    Encoder,
    TextEncoder,
    make_encoder,
    register_encoder,
)
from seminspect.perception.learned import LearnedDetector
from seminspect.perception.observation import Observation
from seminspect.perception.similarity import SceneMatcher, scene_similarity
from seminspect.perception.yolo_seg import ClassMap, YoloSegDetector

__all__ = [
    "Calibration",
    "ClassMap",
    "Encoder",
    "LearnedDetector",
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
