"""Planning: target utility (eq 6), hierarchical and semantic planning, view planning, baselines,
frontier exploration."""

from seminspect.planning.frontier import FrontierPlanner
from seminspect.planning.grid_astar import GridPath
from seminspect.planning.gridmap import CostGrid, CostModel
from seminspect.planning.hierarchical import HierarchicalPlanner, RoutePlan
from seminspect.planning.ompl_planner import OmplPlanner
from seminspect.planning.query import parse_query
from seminspect.planning.routes import LocalPlanner
from seminspect.planning.smoothing import refine_path
from seminspect.planning.utility import UtilityTerms, select_target
from seminspect.planning.view_planner import ViewConstraints, next_view_pose
from seminspect.planning.volumetric import RebuildingVolumetricPlanner, VolumetricPlanner

__all__ = [
    "CostGrid",
    "CostModel",
    "FrontierPlanner",
    "GridPath",
    "HierarchicalPlanner",
    "LocalPlanner",
    "OmplPlanner",
    "RebuildingVolumetricPlanner",
    "RoutePlan",
    "UtilityTerms",
    "ViewConstraints",
    "VolumetricPlanner",
    "next_view_pose",
    "parse_query",
    "refine_path",
    "select_target",
]
