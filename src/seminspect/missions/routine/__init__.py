"""Routine inspection on an outdated map (paper 002): record or load ``M_H``, plan views and a
tour on it, and adapt them to the current site with Algorithm 1 (:mod:`.executive`); the
measures judged against the current world (:mod:`.measures`), task files (:mod:`.tasks`), the
typed figures (:mod:`.metrics`) and the run directory (:mod:`.run`)."""

from seminspect.missions.routine.config import RoutineConfig
from seminspect.missions.routine.executive import RoutineMission
from seminspect.missions.routine.metrics import RoutineMetrics, read_routine_metrics
from seminspect.missions.routine.run import RoutineResult, map_site, run_routine

__all__ = [
    "RoutineConfig",
    "RoutineMetrics",
    "RoutineMission",
    "RoutineResult",
    "map_site",
    "read_routine_metrics",
    "run_routine",
]
