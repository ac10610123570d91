"""Terrain mapping (paper 001, phase 1): drive a sensor rig through a simulated site and fuse
its labelled LiDAR into a metric-semantic cloud; the scene graph of phase 2 is built from it
by :mod:`seminspect.graphs.terrain`."""

from seminspect.missions.terrain.mapping import MappingParams, evaluate_on_world, map_world

__all__ = ["MappingParams", "evaluate_on_world", "map_world"]
