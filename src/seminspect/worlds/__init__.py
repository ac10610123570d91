"""Labelled triangle-mesh worlds (instance / class / part per face), generators and user worlds."""

from seminspect.core.vocabulary import VEHICLE_PARTS
from seminspect.worlds.builder import WorldBuilder
from seminspect.worlds.catalog import WorldSpec, available_worlds, generate_world, open_world
from seminspect.worlds.collision import CollisionMode
from seminspect.worlds.raycast import RayCaster
from seminspect.worlds.underground import mine_drift_pair
from seminspect.worlds.user import insert_world, load_world, load_world_path, save_world
from seminspect.worlds.world import BACKGROUND, GROUND, InstanceInfo, World

__all__ = [
    "BACKGROUND",
    "GROUND",
    "VEHICLE_PARTS",
    "CollisionMode",
    "InstanceInfo",
    "RayCaster",
    "World",
    "WorldBuilder",
    "WorldSpec",
    "available_worlds",
    "generate_world",
    "insert_world",
    "load_world",
    "load_world_path",
    "mine_drift_pair",
    "open_world",
    "save_world",
]
