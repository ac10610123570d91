"""Learned inspection: the semantic deep-RL planner of paper 004.

The policy network (``learning.policy``: 004 Sec III-D, Fig 2) and its recurrent PPO trainer
(``learning.ppo``). Both need torch (the ``rl`` extra); the names below are imported on first
use so that importing the package, or its environment, does not load torch.
"""

from __future__ import annotations

import importlib
from typing import Any

#: Public name -> the module that defines it (imported lazily: torch is an optional extra).
_LAZY = {
    "InspectionPolicy": "seminspect.learning.policy",
    "PolicyConfig": "seminspect.learning.policy",
    "load_policy": "seminspect.learning.ppo",
    "train": "seminspect.learning.ppo",
    "TrainConfig": "seminspect.learning.ppo",
}

__all__ = ["InspectionPolicy", "PolicyConfig", "TrainConfig", "load_policy", "train"]


def __getattr__(name: str) -> Any:
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(_LAZY[name]), name)
