"""Simulated sensors: ray-cast depth + segmentation camera, intensity image, LiDAR, noise models."""
