"""The programs, one subpackage per paper: :mod:`.xflie` (000), :mod:`.terrain` (001),
:mod:`.routine` (002) and :mod:`.learning` (004).

The names of the default program, the xFLIE mission, are re-exported here.
"""

from seminspect.missions.xflie import XFlie
from seminspect.missions.xflie.config import MissionConfig, make_config
from seminspect.missions.xflie.run import MissionResult, run_mission

__all__ = ["MissionConfig", "MissionResult", "XFlie", "make_config", "run_mission"]
