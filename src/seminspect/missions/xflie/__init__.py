"""The xFLIE program (000): an explore-inspect-explore mission that builds a 3DLSG.

The executive (000 Sec V) is a short loop over one module per phase:

* :mod:`.executive`: :class:`XFlie`, the loop that runs the phases in turn;
* :mod:`.context`: :class:`MissionContext`, the state the phases share;
* :mod:`.sightings`: registering detections (eqs 3-5) and finding one target in a frame;
* :mod:`.exploration`: 360-degree surveys and frontier hops, with their memory;
* :mod:`.approach`: the route to a selected target (graph leg, then local) and its confirmation;
* :mod:`.inspection`: ``π^insp`` level by level (eqs 7, 9, 10) and climbing;
* :mod:`.surface`: surface tracking and view steps (002 eqs 1-2);
* :mod:`.completion`: the end of a level by scene similarity (eq 8) or the safety cap;
* :mod:`.links`: Target-layer edges between inspected targets and their first routes;
* :mod:`.team`: an explorer and an inspector, two executives on one graph (beyond 000).

Around it: :mod:`.config` (the mission's settings), :mod:`.navigation` (driving routes while
sensing), :mod:`.recorder` and :mod:`.metrics` (what happened, typed), :mod:`.build` (world,
robot, map and executive from a configuration), :mod:`.run` and :mod:`.team_run` (a run
directory end to end), :mod:`.scoring` and :mod:`.figures` (the graph against the world's
truth), :mod:`.queries` (the operator's queries), :mod:`.layout` and :mod:`.outputs` (the run's
files), :mod:`.summary`, :mod:`.frontier` (the explore-only baseline of 000 Table 6),
:mod:`.sweep` (its part in a sweep) and :mod:`.replay` (a run's LiDAR as a ROS bag).
"""

from seminspect.missions.xflie.approach import PLANNING_MARGIN
from seminspect.missions.xflie.context import MissionContext
from seminspect.missions.xflie.executive import MissionProgress, XFlie

__all__ = ["PLANNING_MARGIN", "MissionContext", "MissionProgress", "XFlie"]
