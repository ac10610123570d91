"""Missions: the xFLIE explore-inspect-explore executive and its run directory."""

from seminspect.missions.config import MissionConfig, ResolvedMissionConfig, make_config, resolve
from seminspect.missions.metrics import MissionMetrics
from seminspect.missions.platform import Platform, SimulatedPlatform
from seminspect.missions.recorder import MissionRecorder
from seminspect.missions.run import MissionResult, run_mission
from seminspect.missions.rundir import RunDirectory
from seminspect.missions.terrain_mapping import map_world
from seminspect.missions.xflie import XFlie

__all__ = [
    "MissionConfig",
    "MissionMetrics",
    "MissionRecorder",
    "MissionResult",
    "Platform",
    "ResolvedMissionConfig",
    "RunDirectory",
    "SimulatedPlatform",
    "XFlie",
    "make_config",
    "map_world",
    "resolve",
    "run_mission",
]
