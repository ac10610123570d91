"""Simulated sensors: ray-cast depth + segmentation camera, intensity image, the detector seam,
LiDAR, noise models."""

from seminspect.sensors.camera import CameraModel, Frame, render
from seminspect.sensors.detector import Detector, TruthDetector
from seminspect.sensors.lidar import Lidar, LidarScan
from seminspect.sensors.noise import NoiseModel, make_noise, noise_preset, require_rng
from seminspect.sensors.segmentation import Detection, detect, detect_instances, detect_parts

__all__ = [
    "CameraModel",
    "Detection",
    "Detector",
    "Frame",
    "Lidar",
    "LidarScan",
    "NoiseModel",
    "TruthDetector",
    "detect",
    "detect_instances",
    "detect_parts",
    "make_noise",
    "noise_preset",
    "render",
    "require_rng",
]
