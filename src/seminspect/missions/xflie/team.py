"""Two robots, one 3DLSG: an explorer fills the Target layer, then both inspect.

Beyond 000, after its Sec IX (heterogeneous robots sharing one graph). Each robot is a whole
:class:`XFlie` (its own platform, navigator, trajectory and clock) built on the same
:class:`LayeredSemanticGraph` (and, as :mod:`seminspect.missions.team_run` builds them, the same
occupancy map); the team only decides which phase each one runs next.

* The **explorer, then inspector** runs ``π^expl:360`` where it starts, then frontier hops
  with a survey at each, until no frontier is left or its hop cap is spent; every frame it
  takes (surveys and transit) registers its target detections in the shared graph. Once
  exploration is done it takes targets exactly as the inspector does.
* The **inspector** takes the next target by eq (6) from the shared graph, with its own pose
  as the robot state ``x_k``, then approaches, confirms and inspects it (Level, Pose and
  Feature layers) with the single-robot phases.
* **Claims.** A robot that selects a target claims it in the graph
  (:class:`~seminspect.graphs.lsg.claims.TargetClaims`) and releases it when the pursuit
  ends (inspected, unreachable or discarded); the other robot never selects a target claimed
  at its own clock. With no free target a robot **waits** until the other's clock if that is
  ahead (it may find or free one meanwhile), else it stops; both stop at the budget.

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
own clock. A claim, though, covers the whole step on the claimant's clock, so a target the
other robot was pursuing at a given moment is never free to take at that moment, even when
the pursuit has already ended (and failed) in the order the steps were simulated. Everything
is deterministic under the mission's seed. The robots do not perceive each other (the
simulator has no robot-robot collisions).
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
    """What both roles share: the robot's mission, its clock, why it stopped (once done), and
    taking targets from the shared graph by eq (6), under a claim."""

    role = ""

    def __init__(self, mission: XFlie) -> None:
        self.mission = mission
        self.started = False
        self.stop_reason = ""
        #: The other robot of the team (set by :class:`Team`).
        self.partner: TeamRobot | None = None
        #: Targets this robot inspected, in order.
        self.inspected: list[str] = []

    @property
    def clock(self) -> float:
        return self.mission.platform.time

    @property
    def done(self) -> bool:
        return bool(self.stop_reason)

    def inspect_next(self, start: float) -> Activity:
        """Claim the next target by eq (6) from this robot's pose, pursue it, release it; or
        wait for the partner when no target is free."""
        mission = self.mission
        if mission.time_left <= MIN_INSPECTION_S:
            self._stop("time budget spent")
            return Activity(self.role, "stop", start, start)
        platform, claims = mission.platform, mission.graph.claims
        # Eq (6)'s proximity term is measured from this robot, not the one that saw last.
        mission.graph.update_robot(platform.position, quat_from_yaw(platform.yaw), platform.time)
        choice = mission.select(taken=claims.taken_from(self.role, start))
        if choice is None:
            return self._wait(start)
        claims.claim(choice.target_id, self.role, start)
        target = mission.graph.target(choice.target_id)
        inspected = mission.pursue(target) and target.inspected
        claims.release(choice.target_id, self.clock)
        if inspected:
            self.inspected.append(target.id)
        return Activity(
            self.role, "inspect" if inspected else "skip", start, self.clock, choice.target_id
        )

    def _wait(self, start: float) -> Activity:
        """No target is free: stand still until the partner's clock if it is ahead (it may
        find or free one meanwhile), else stop."""
        partner = self.partner
        if partner is None or partner.done or partner.clock <= start:
            self._stop("every target taken")
            return Activity(self.role, "stop", start, start)
        self.mission.platform.wait(partner.clock - start)
        self.mission.ctx.on_step()
        return Activity(self.role, "wait", start, self.clock)

    def _stop(self, reason: str) -> None:
        self.stop_reason = reason


class Explorer(TeamRobot):
    """The explorer, then an inspector: the first survey, one frontier hop (and survey) per
    step until exploration is done, then targets by eq (6) like the inspector."""

    role = "explorer"

    def __init__(self, mission: XFlie) -> None:
        super().__init__(mission)
        self.hops = 0
        #: Why exploration ended ("" while it runs).
        self.explored = ""

    def step(self) -> Activity:
        mission, start = self.mission, self.clock
        if not self.started:
            self.started = True
            mission.begin()
            return Activity(self.role, "survey", start, self.clock)
        if self.explored:
            return self.inspect_next(start)
        if mission.time_left <= 0:
            self._stop("time budget spent")
        elif self.hops >= mission.config.exploration.frontier_max_hops:
            self.explored = "frontier hop cap reached"
        elif not mission.explore():
            self.explored = "no frontier left"
        else:
            self.hops += 1
        return Activity(self.role, "explore", start, self.clock)

    def _stop(self, reason: str) -> None:
        self.stop_reason = f"{self.explored}, then {reason}" if self.explored else reason


class Inspector(TeamRobot):
    """The inspector: targets by eq (6) from the start, waiting for the explorer when none is
    free."""

    role = "inspector"

    def step(self) -> Activity:
        if not self.started:  # its own map starts with what the LiDAR sees from the start
            self.started = True
            self.mission.navigator.sense_lidar()
        return self.inspect_next(self.clock)


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
        self.inspector = Inspector(inspector)
        self.explorer.partner, self.inspector.partner = self.inspector, self.explorer
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
