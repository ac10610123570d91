"""The programs, one subpackage per paper: :mod:`.xflie` (000), :mod:`.terrain` (001),
:mod:`.routine` (002) and :mod:`.learning` (004).

The names of the default program, the xFLIE mission, are re-exported here. They are imported
on first use, so that importing another program does not load the xFLIE one.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from seminspect.missions.xflie import XFlie
    from seminspect.missions.xflie.config import MissionConfig, make_config
    from seminspect.missions.xflie.run import MissionResult, run_mission

#: Public name -> the module that defines it.
_LAZY = {
    "MissionConfig": "seminspect.missions.xflie.config",
    "MissionResult": "seminspect.missions.xflie.outputs",
    "XFlie": "seminspect.missions.xflie",
    "make_config": "seminspect.missions.xflie.config",
    "run_mission": "seminspect.missions.xflie.run",
}

__all__ = ["MissionConfig", "MissionResult", "XFlie", "make_config", "run_mission"]


def __getattr__(name: str) -> Any:
    if name not in _LAZY:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(_LAZY[name]), name)
