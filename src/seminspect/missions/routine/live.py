"""A routine mission seen while it runs: the state a live view draws, handed out at its pace.

:class:`LiveWatch` is the mission's :class:`~seminspect.missions.routine.executive.RoutineWatch`.
When it is attached, its :class:`LiveFeed` gets the run's :class:`LiveScene` (``M_H``, the
regions and every planned view); then, after each leg of driving and each view, whenever the
feed is ready for more (a client is connected and the last state is old enough), a
:class:`LiveState`: the robot's pose and path, the last view's frame, ``M_C``, the task being
inspected with its views and coverage, and the last cycle's decision (``Γ_s`` against ``Γ_t``).
It only reads, so a watched mission decides exactly as an unwatched one, and it costs nothing
while the feed is not ready. Routine missions have no time budget: they end when every task is
done or given up.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from seminspect.mapping.voxel import VoxelMap
from seminspect.missions.routine.executive import RoutineMission, ViewSample
from seminspect.sensors import Frame


@dataclass(frozen=True)
class TaskRegion:
    """One inspection task as the scene shows it: its region's outline and its planned views."""

    name: str
    outline: NDArray[np.float64]
    views: NDArray[np.float64]


@dataclass(frozen=True)
class LiveScene:
    """What does not change during a run: ``M_H`` (the mission's own, read during
    :meth:`LiveFeed.start`) and the tasks."""

    prior: VoxelMap
    tasks: tuple[TaskRegion, ...]


@dataclass(frozen=True)
class ActiveView:
    """The task being inspected: its views (visiting order during the tour), each one's
    outcome (True tracked, False unreachable, None not yet) and its ROI coverage so far."""

    index: int
    name: str
    views: NDArray[np.float64]
    outcomes: tuple[bool | None, ...]
    toured: bool  # whether its tour has started (``views`` are in visiting order)
    coverage_pct: float | None
    flown: NDArray[np.float64]  # where this task's views were taken from (Π_LVP when adapted)


@dataclass(frozen=True)
class LiveState:
    """The mission as it stands, for one picture of the live view.

    ``current_map`` is the mission's own ``M_C``, not a copy: a feed reads it during
    :meth:`LiveFeed.publish` and keeps nothing of it after it returns.

    Attributes:
        sim_time: simulated time so far [s].
        phase: ``start``, ``navigate`` (to a task), ``tour`` (its views) or ``done``.
        trajectory: ``(n, 5)`` rows so far (time, true position, yaw).
        frame: the last view's camera frame (None before the first).
        task: the task being worked on, or the last one (None before the first).
        last_cycle: the last Algorithm 1 cycle's record (``Γ_s``, adapted, utility, ...).
        gamma_t: the threshold ``Γ_s`` is compared with.
        tasks_done, tasks_total: tasks completed so far, and all of them.
        collisions: contacts so far.
        ended, reason: how the run ended (``completed``, ``interrupted``, ``failed``) and
            why, in its last state; None while it runs.
    """

    sim_time: float
    phase: str
    trajectory: NDArray[np.float64]
    current_map: VoxelMap
    frame: Frame | None
    task: ActiveView | None
    last_cycle: ViewSample | None
    gamma_t: float
    tasks_done: int
    tasks_total: int
    collisions: int
    ended: str | None = None
    reason: str = ""


class LiveFeed(Protocol):
    """Where a watched mission's states go (the live view's server)."""

    def start(self, scene: LiveScene) -> None:
        """The run's scene, before its first state."""
        ...

    def ready(self) -> bool:
        """Whether a new state is wanted now (cheap: asked at every sensing step)."""
        ...

    def publish(self, state: LiveState) -> None:
        """Take a state, reading the map before returning."""
        ...


class LiveWatch:
    """Shows a routine mission to a :class:`LiveFeed` (see the module docstring)."""

    def __init__(self, feed: LiveFeed) -> None:
        self.feed = feed
        self._mission: RoutineMission | None = None

    def attach(self, mission: RoutineMission) -> None:
        """Watch ``mission`` from its next sensing step on; the feed gets its scene now."""
        self.feed.start(scene_of(mission))
        self._mission = mission
        mission.watch = self

    def step(self, frame: Frame | None) -> None:
        """A sensing step (the frame is the mission's ``frame`` by now): a state if wanted."""
        if self.feed.ready():
            self.publish()

    def publish(self, ended: str | None = None, reason: str = "") -> None:
        """Hand the feed the mission's state now (nothing before :meth:`attach`)."""
        if self._mission is not None:
            self.feed.publish(self.state(ended, reason))

    def state(self, ended: str | None = None, reason: str = "") -> LiveState:
        """The attached mission's state."""
        mission = self._mission
        if mission is None:
            raise RuntimeError("LiveWatch.state() before attach()")
        log = mission.robot.trajectory
        return LiveState(
            sim_time=mission.robot.time,
            phase=mission.phase,
            trajectory=np.column_stack([log.time, log.position, log.yaw]),
            current_map=mission.current_map,
            frame=mission.frame,
            task=_active_view(mission),
            last_cycle=mission.samples[-1] if mission.samples else None,
            gamma_t=mission.config.gamma_t,
            tasks_done=sum(t.completed for t in mission.tasks),
            tasks_total=len(mission.tasks),
            collisions=mission.collisions,
            ended=ended,
            reason=reason,
        )


def scene_of(mission: RoutineMission) -> LiveScene:
    """The static part of a mission's view: ``M_H``, each task's outline and planned views."""
    tasks = tuple(
        TaskRegion(plan.region.name, plan.region.vertices, plan.positions) for plan in mission.plans
    )
    return LiveScene(mission.prior, tasks)


def _active_view(mission: RoutineMission) -> ActiveView | None:
    active = mission.active
    if active is None:
        return None
    name = mission.plans[active.index].region.name
    flown = [(s.x, s.y, s.z) for s in mission.samples if s.task == name]
    coverage = None if active.coverage is None else active.coverage.percent
    return ActiveView(
        index=active.index,
        name=name,
        views=active.views,
        outcomes=tuple(active.outcomes),
        toured=active.coverage is not None,
        coverage_pct=coverage,
        flown=np.array(flown, dtype=float).reshape(-1, 3),
    )
