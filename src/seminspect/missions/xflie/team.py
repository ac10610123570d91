"""Two robots, one 3DLSG: an explorer fills the Target layer, an inspector the layers below.

Beyond 000, after its Sec IX (heterogeneous robots sharing one graph). Each robot is a whole
:class:`XFlie` (its own platform, occupancy map, navigator, trajectory and clock) built on the
same :class:`LayeredSemanticGraph`; the team only decides which phase each one runs next.

* The **explorer** runs ``π^expl:360`` where it starts, then frontier hops with a survey at
  each, until no frontier is left, its hop cap is spent or its budget ends. Every frame it
  takes (surveys and transit) registers its target detections in the shared graph.
* The **inspector** takes the next target by eq (6) from the shared graph, with its own pose
  as the robot state ``x_k``, then approaches, confirms and inspects it (Level, Pose and
  Feature layers) with the single-robot phases. With no target to take it **waits** until the
  explorer's clock catches up (the explorer may find one meanwhile); it is done when the
  explorer is done and no uninspected target is left, or at the budget.

**Merge rule.** Every detection, whichever robot made it, goes through the graph's own
registration and Φ (eqs 3-5), with ``x_k`` the pose of the robot that took the frame: a
detection within ``d_check^T`` of an existing target merges into it (the larger mask sets its
attributes, never once it is inspected), one near an inspected target inside the camera's view
is rejected, anything else is a new target. The robots start at the same pose, so their
odometry frames coincide at the start and the graph needs no alignment between them.

**Scheduling** is discrete-event interleaving of whole steps (a survey, a frontier hop, the
pursuit of one target, a wait): the robot whose clock is behind takes its next step; on a
tie the explorer goes first, so a target found at time ``t`` is there for an inspector choosing
at ``t``. Steps are atomic, so one robot's inspection never sees the other change the graph
half-way; the cost is that a robot may see what the other found up to one step ahead of its
own clock. Everything is deterministic under the mission's seed. The robots do not perceive
each other (the simulator has no robot-robot collisions).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.missions.xflie.executive import MIN_INSPECTION_S, XFlie

#: The order the scheduler breaks ties in: the explorer's finds come first.
ROLES = ("explorer", "inspector")


@dataclass(frozen=True)
class Activity:
    """One step of one robot: what it did, from when to when (simulated seconds)."""

    robot: str
    activity: str
    start: float
    end: float
    target: str | None = None


class Member(Protocol):
    """A robot the scheduler can advance: its clock, whether it is done, its next step."""

    @property
    def clock(self) -> float: ...

    @property
    def done(self) -> bool: ...

    def step(self) -> Activity: ...


def interleave(members: Sequence[Member], on_step: Callable[[Activity], None]) -> None:
    """Advance the member whose clock is behind, one step at a time, until every one is done.

    Ties go to the member listed first. A member must end each step done or with its clock
    moved on, so the loop always ends.
    """
    while True:
        active = [m for m in members if not m.done]
        if not active:
            return
        on_step(min(active, key=lambda m: m.clock).step())


class TeamRobot:
    """What both roles share: the robot's mission, its clock, and why it stopped (once done)."""

    role = ""

    def __init__(self, mission: XFlie) -> None:
        self.mission = mission
        self.started = False
        self.stop_reason = ""

    @property
    def clock(self) -> float:
        return self.mission.platform.time

    @property
    def done(self) -> bool:
        return bool(self.stop_reason)


class Explorer(TeamRobot):
    """The explorer's steps: the first survey, then one frontier hop (and survey) per step."""

    role = "explorer"

    def __init__(self, mission: XFlie) -> None:
        super().__init__(mission)
        self.hops = 0

    def step(self) -> Activity:
        mission, start = self.mission, self.clock
        if not self.started:
            self.started = True
            mission.begin()
            return Activity(self.role, "survey", start, self.clock)
        if mission.time_left <= 0:
            self.stop_reason = "time budget spent"
        elif self.hops >= mission.config.exploration.frontier_max_hops:
            self.stop_reason = "frontier hop cap reached"
        elif not mission.explore():
            self.stop_reason = "no frontier left"
        else:
            self.hops += 1
        return Activity(self.role, "explore", start, self.clock)


class Inspector(TeamRobot):
    """The inspector's steps: pursue the next target by eq (6), or wait for the explorer."""

    role = "inspector"

    def __init__(self, mission: XFlie, explorer: Explorer) -> None:
        super().__init__(mission)
        self.explorer = explorer
        #: Targets this robot inspected, in order.
        self.inspected: list[str] = []

    def step(self) -> Activity:
        mission, start = self.mission, self.clock
        if not self.started:  # its own map starts with what the LiDAR sees from the start
            self.started = True
            mission.navigator.sense_lidar()
        if mission.time_left <= MIN_INSPECTION_S:
            self.stop_reason = "time budget spent"
            return Activity(self.role, "stop", start, start)
        platform = mission.platform
        # Eq (6)'s proximity term is measured from this robot, not the one that saw last.
        mission.graph.update_robot(platform.position, quat_from_yaw(platform.yaw), platform.time)
        choice = mission.select()
        if choice is None:
            return self._wait(start)
        target = mission.graph.target(choice.target_id)
        inspected = mission.pursue(target) and target.inspected
        if inspected:
            self.inspected.append(target.id)
        return Activity(
            self.role, "inspect" if inspected else "skip", start, self.clock, choice.target_id
        )

    def _wait(self, start: float) -> Activity:
        """No target to take: done if the explorer is, else stand still until it is level."""
        if self.explorer.done:
            self.stop_reason = "every target taken and exploration done"
            return Activity(self.role, "stop", start, start)
        self.mission.platform.wait(max(self.explorer.clock - start, 0.0))
        self.mission.ctx.on_step()
        return Activity(self.role, "wait", start, self.clock)


class Team:
    """An explorer and an inspector on one graph, interleaved by their clocks.

    Args:
        explorer: the explorer's mission (its phases are used for exploring only).
        inspector: the inspector's mission, built on the explorer's graph.
        on_step: called with every step taken (e.g. to log it).
    """

    def __init__(
        self,
        explorer: XFlie,
        inspector: XFlie,
        on_step: Callable[[Activity], None] | None = None,
    ) -> None:
        if inspector.graph is not explorer.graph:
            raise InvalidInputError("the explorer and the inspector must share one graph")
        self.explorer = Explorer(explorer)
        self.inspector = Inspector(inspector, self.explorer)
        self.activities: list[Activity] = []
        self._on_step = on_step

    @property
    def members(self) -> tuple[Explorer, Inspector]:
        return (self.explorer, self.inspector)

    @property
    def time(self) -> float:
        """The team's mission time: the later of the two clocks."""
        return max(m.clock for m in self.members)

    def execute(self) -> str:
        """Run both robots until both are done; returns why each stopped."""
        interleave(self.members, self._record)
        return "; ".join(f"{m.role}: {m.stop_reason}" for m in self.members)

    def _record(self, activity: Activity) -> None:
        self.activities.append(activity)
        if self._on_step is not None:
            self._on_step(activity)
