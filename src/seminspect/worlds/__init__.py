"""Labelled triangle-mesh worlds (instance / class / part per face), generators, user worlds
and site files (several meshes, or a Gazebo SDF world)."""

from seminspect.core.vocabulary import VEHICLE_PARTS
from seminspect.worlds.builder import WorldBuilder
from seminspect.worlds.catalog import WorldSpec, available_worlds, generate_world, open_world
from seminspect.worlds.collision import CollisionMode
from seminspect.worlds.raycast import RayCaster
from seminspect.worlds.sdf import SiteWarning, load_sdf
from seminspect.worlds.site import load_site
from seminspect.worlds.site_check import Finding, check_world
from seminspect.worlds.underground import mine_drift_pair
from seminspect.worlds.user import insert_world, load_world, load_world_path, save_world
from seminspect.worlds.world import BACKGROUND, GROUND, InstanceInfo, World

__all__ = [
    "BACKGROUND",
    "GROUND",
    "VEHICLE_PARTS",
    "CollisionMode",
    "Finding",
    "InstanceInfo",
    "RayCaster",
    "SiteWarning",
    "World",
    "WorldBuilder",
    "WorldSpec",
    "available_worlds",
    "check_world",
    "generate_world",
    "insert_world",
    "load_sdf",
    "load_site",
    "load_world",
    "load_world_path",
    "mine_drift_pair",
    "open_world",
    "save_world",
]
