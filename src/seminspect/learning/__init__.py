"""Learned inspection (004): the semantic inspection environment, its policy and training."""

from seminspect.learning.baselines import Controller, OrbitController, RandomController
from seminspect.learning.env import EnvConfig, InspectionEnv, InspectionVectorEnv
from seminspect.learning.evaluation import EpisodeTrace, EvaluationResult, evaluate
from seminspect.learning.rooms import Room, sample_room

__all__ = [
    "Controller",
    "EnvConfig",
    "EpisodeTrace",
    "EvaluationResult",
    "InspectionEnv",
    "InspectionVectorEnv",
    "OrbitController",
    "RandomController",
    "Room",
    "evaluate",
    "sample_room",
]
