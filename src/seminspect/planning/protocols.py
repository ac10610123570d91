"""The contracts every grid planner keeps, so a program can take any of them.

Two kinds of grid planner exist, and the difference is the map's lifetime, not the search:

* a :class:`RoutePlanner` plans on the map it is handed at each call: the robot's own map,
  which changes between calls (:class:`~seminspect.planning.routes.LocalPlanner`, the mission's
  planner; :class:`~seminspect.planning.volumetric.RebuildingVolumetricPlanner`, 000's
  volumetric baseline inside a mission). The xFLIE navigator drives with one.
* a :class:`FixedMapPlanner` is built once on one map and answers many queries on it
  (:class:`~seminspect.planning.volumetric.VolumetricPlanner`, the baseline of 000 Table 5;
  :class:`~seminspect.planning.ompl_planner.OmplPlanner`, an RRT-Connect peer).

Both return a :class:`~seminspect.planning.grid_astar.GridPath` from ``start`` to ``goal`` (or to
a free point within ``goal_radius`` of it) and raise
:class:`~seminspect.core.errors.PlanningError` when there is none; ``tests/planning/
test_protocols.py`` holds every planner to that. The graph planner
(:class:`~seminspect.planning.hierarchical.HierarchicalPlanner`) answers a different question,
a route to a node of the 3DLSG, and has its own contract (``RoutePlan``).
"""

from __future__ import annotations

from typing import Protocol

from numpy.typing import ArrayLike

from seminspect.mapping.voxel import VoxelMap
from seminspect.planning.grid_astar import GridPath


class RoutePlanner(Protocol):
    """A route on the map of the moment (the robot's own, changing between calls)."""

    def plan(
        self, voxel_map: VoxelMap, start: ArrayLike, goal: ArrayLike, goal_radius: float = 0.0
    ) -> GridPath: ...


class FixedMapPlanner(Protocol):
    """A route on the map the planner was built on."""

    def plan(self, start: ArrayLike, goal: ArrayLike, goal_radius: float = 0.0) -> GridPath: ...
