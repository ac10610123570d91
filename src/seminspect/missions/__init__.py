"""Missions: the xFLIE explore-inspect-explore executive, the frontier explorer, run directories."""

from seminspect.missions.config import MissionConfig, ResolvedMissionConfig, make_config, resolve
from seminspect.missions.frontier_mission import FrontierMission
from seminspect.missions.metrics import MissionMetrics
from seminspect.missions.platform import Platform, SimulatedPlatform
from seminspect.missions.recorder import MissionRecorder
from seminspect.missions.run import MissionResult, run_mission
from seminspect.missions.rundir import RunDirectory
from seminspect.missions.terrain_mapping import map_world
from seminspect.missions.xflie import XFlie

__all__ = [
    "FrontierMission",
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
