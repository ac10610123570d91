"""What a mission records as it runs: wall time per category, decisions, plans, level endings.

The executive and its phases report here instead of keeping logs of their own; the run's
metrics (:mod:`seminspect.missions.xflie.metrics`) are computed from the :class:`MissionRecord` it
yields, never from the executive's internals.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal, Protocol

from seminspect.missions.xflie.metrics import CoverageRecorder, LevelEndings, Timers
from seminspect.planning.hierarchical import RoutePlan

#: Why a level ended: eq (8) scene similarity, or the sweep / pose safety cap.
LevelEnding = Literal["similarity", "cap"]


class EventSink(Protocol):
    """Where decisions go (a run directory's ``events.jsonl``)."""

    def log_event(self, kind: str, sim_time: float, **fields: Any) -> None: ...


@dataclass(frozen=True)
class PlanningRecord:
    """One hierarchical planning query made during the mission."""

    goal: str
    seconds: float
    target_layer_s: float
    local_layers_s: float
    length: float
    settled: int


@dataclass
class MissionRecord:
    """Everything the recorder holds, for the run's metrics."""

    seconds_by_category: dict[str, float]
    plans: list[PlanningRecord] = field(default_factory=list)
    level_endings: LevelEndings = field(default_factory=LevelEndings)


class MissionRecorder:
    """Timers, the event log, plan records, level endings and coverage of one mission.

    Args:
        clock: the mission's simulated time (events are stamped with it).
        coverage: what the inspections saw of each target.
        sink: where events go; ``None`` drops them.
        robot: the robot's name, when it is one of a team (its events carry it).
    """

    def __init__(
        self,
        clock: Callable[[], float],
        coverage: CoverageRecorder,
        sink: EventSink | None = None,
        robot: str | None = None,
    ) -> None:
        self.timers = Timers()
        self.coverage = coverage
        self._clock = clock
        self._sink = sink
        self._tags = {} if robot is None else {"robot": robot}
        self._plans: list[PlanningRecord] = []
        self._endings = LevelEndings()

    def event(self, kind: str, **fields: object) -> None:
        """One decision of the mission, stamped with the simulated time."""
        if self._sink is not None:
            self._sink.log_event(kind, self._clock(), **self._tags, **fields)

    def plan(self, goal: str, plan: RoutePlan) -> None:
        """Keep a hierarchical query's timing for the Table 3 planning-time column."""
        timing = plan.timing
        self._plans.append(
            PlanningRecord(
                goal,
                timing.total_s,
                timing.target_layer_s,
                timing.local_layers_s,
                plan.length,
                plan.settled,
            )
        )

    def level_ended(self, reason: LevelEnding) -> None:
        if reason == "similarity":
            self._endings.similarity += 1
        else:
            self._endings.cap += 1

    @property
    def plans(self) -> list[PlanningRecord]:
        return list(self._plans)

    def record(self) -> MissionRecord:
        """A snapshot of everything recorded so far."""
        return MissionRecord(
            dict(self.timers.seconds),
            list(self._plans),
            LevelEndings(self._endings.similarity, self._endings.cap),
        )
