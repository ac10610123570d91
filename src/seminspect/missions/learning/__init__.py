"""Learned inspection: the semantic deep-RL planner of paper 004.

The rooms and vector environment, baselines, evaluation and the training settings need only
numpy, numba, pydantic and gymnasium. The policy network (``learning.policy``: 004 Sec III-D,
Fig 2) and its recurrent PPO trainer (``learning.ppo``, with ``learning.rollout`` and
``learning.checkpoints``) need torch (the ``rl`` extra); those names are imported on first use,
so importing the package, or its environment, does not load torch.
"""

from __future__ import annotations

import importlib
from typing import Any

from seminspect.missions.learning.baselines import Controller, OrbitController, RandomController
from seminspect.missions.learning.env import InspectionVectorEnv
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.evaluation import EpisodeTrace, EvaluationResult, evaluate
from seminspect.missions.learning.rooms import Room, sample_room
from seminspect.missions.learning.single_env import InspectionEnv
from seminspect.missions.learning.train_config import TrainConfig

#: Public name -> the module that defines it (imported lazily: torch is an optional extra).
_LAZY = {
    "InspectionPolicy": "seminspect.missions.learning.policy",
    "PolicyConfig": "seminspect.missions.learning.policy",
    "load_policy": "seminspect.missions.learning.checkpoints",
    "train": "seminspect.missions.learning.ppo",
    "LearnedController": "seminspect.missions.learning.agent",
    "load_controller": "seminspect.missions.learning.agent",
}

__all__ = [
    "Controller",
    "EnvConfig",
    "EpisodeTrace",
    "EvaluationResult",
    "InspectionEnv",
    "InspectionPolicy",
    "InspectionVectorEnv",
    "LearnedController",
    "OrbitController",
    "PolicyConfig",
    "RandomController",
    "Room",
    "TrainConfig",
    "evaluate",
    "load_controller",
    "load_policy",
    "sample_room",
    "train",
]


def __getattr__(name: str) -> Any:
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(_LAZY[name]), name)
