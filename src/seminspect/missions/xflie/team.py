"""Two robots, one 3DLSG: both explore and both inspect; an explorer and an inspector differ
in what each prefers.

Beyond 000, after its Sec IX (heterogeneous robots sharing one graph). Each robot is a whole
:class:`XFlie` (its own platform, navigator, trajectory and clock) built on the same
:class:`LayeredSemanticGraph` (and, as :mod:`seminspect.missions.xflie.team_run` builds them,
the same occupancy map); the team only decides which phase each one runs next.

* The **explorer** prefers exploring: ``π^expl:360`` where it starts, then frontier hops with a
  survey at each (the mission's own nearest-frontier rule, unrestricted), until no frontier is
  left to try or the team's hop cap is spent (a hop that could reach none of the frontiers it
  tried leaves the farther ones for its next step, where a lone robot would stop); every
  frame it takes (surveys and transit) registers its target detections in the shared graph.
  Before each hop it first takes a free target by eq (6), but only among those **nearer to it
  than to the inspector** (a vehicle it has just found beside it, not one across the site);
  once exploration is done it takes any free target, exactly as the inspector does.
* The **inspector** prefers inspecting: the next free target by eq (6) from the shared graph,
  with its own pose as the robot state ``x_k``, approached, confirmed and inspected (Level,
  Pose and Feature layers) with the single-robot phases. With no free target it **explores**
  rather than stand idle: a frontier hop and a survey with the same machinery, but while the
  explorer still explores only among frontiers **nearer to it than to the explorer** (the
  bisector between the two robots splits the frontiers, so they never chase the same one) or
  that the explorer has spent (tried, and will not try again); once the explorer is done, any
  frontier. The two robots' hops count against one cap, the mission's ``frontier_max_hops``;
  each remembers the frontiers it spent (a frontier one robot could not reach from where it
  was stays a candidate for the other).
* **Claims.** A robot that selects a target claims it in the graph
  (:class:`~seminspect.graphs.lsg.claims.TargetClaims`) and releases it when the pursuit
  ends (inspected, unreachable or discarded); the other robot never selects a target claimed
  at its own clock. With no free target and nothing it may explore, a robot **waits** until
  the other's clock if that is ahead (it may find or free a target, or open or leave a
  frontier, meanwhile), else it stops; both stop at the budget. The team is done when neither
  robot has a frontier left and every target is inspected or given up.

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
half-way; the cost is that the graph may hold what the other robot found up to one step
ahead of this one's clock. So a robot does not select a target last seen after its own clock
(it is not yet known then; the robot waits for the other if nothing else is free), and a
claim covers the whole step on the claimant's clock, so a target the other robot was pursuing
at a given moment is never free to take at that moment, even when the pursuit has already
ended (and failed) in the order the steps were simulated. Everything is deterministic under
the mission's seed. The robots do not perceive each other (the simulator has no robot-robot
collisions).
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.graphs.lsg.model import TargetStatus
from seminspect.missions.xflie.executive import MIN_INSPECTION_S, XFlie
from seminspect.planning.utility import UtilityTerms

#: The order the scheduler breaks ties in: the explorer's finds come first.
ROLES = ("explorer", "inspector")

#: How a frontier hop ended: reached, every frontier tried missed, or none left to try.
Hop = Literal["hopped", "missed", "none left"]


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

    Ties go to the member listed first. A member must end each step done, with its clock
    moved on, or with less left to try (a frontier it missed is not tried again), so the loop
    always ends.
    """
    while True:
        active = [m for m in members if not m.done]
        if not active:
            return
        on_step(min(active, key=lambda m: m.clock).step())


class TeamRobot:
    """What both roles share: the robot's mission, its clock, why it stopped (once done),
    taking targets from the shared graph by eq (6) under a claim, and frontier hops."""

    role = ""

    def __init__(self, mission: XFlie) -> None:
        self.mission = mission
        self.started = False
        self.stop_reason = ""
        #: The other robot of the team (set by :class:`Team`).
        self.partner: TeamRobot | None = None
        #: Targets this robot inspected, in order.
        self.inspected: list[str] = []
        #: Frontier hops this robot made (the team shares one cap).
        self.hops = 0

    @property
    def clock(self) -> float:
        return self.mission.platform.time

    @property
    def done(self) -> bool:
        return bool(self.stop_reason)

    @property
    def exploring(self) -> bool:
        """Whether this robot may still take frontier hops."""
        return not self.done

    def inspect_next(self, start: float) -> Activity:
        """Claim the next target by eq (6) from this robot's pose, pursue it, release it; or,
        when no target is free, :meth:`_when_none_free`, else wait for the partner."""
        if self.mission.time_left <= MIN_INSPECTION_S:
            self._stop("time budget spent")
            return Activity(self.role, "stop", start, start)
        choice = self._select(start)
        if choice is None:
            return self._when_none_free(start) or self._wait(start)
        return self._pursue(choice.target_id, start)

    def _when_none_free(self, start: float) -> Activity | None:
        """What this robot does when no target is free to take (None: wait)."""
        return None

    def _select(self, start: float, also_taken: Collection[str] = ()) -> UtilityTerms | None:
        """Eq (6) from this robot's pose over the targets no other robot holds at ``start``,
        already seen by then, and not in ``also_taken``."""
        mission = self.mission
        platform = mission.platform
        # Eq (6)'s proximity term is measured from this robot, not the one that saw last.
        mission.graph.update_robot(platform.position, quat_from_yaw(platform.yaw), platform.time)
        taken = mission.graph.claims.taken_from(self.role, start).union(also_taken)
        return mission.select(taken=taken | self._seen_after(start))

    def _seen_after(self, start: float) -> set[str]:
        """Targets last seen after ``start`` (by the other robot, a step ahead): not yet
        known at this robot's clock."""
        return {t.id for t in self.mission.graph.targets(TargetStatus.DETECTED) if t.stamp > start}

    def _pursue(self, target_id: str, start: float) -> Activity:
        """Claim a target, approach, confirm and inspect it, and release it."""
        mission, claims = self.mission, self.mission.graph.claims
        claims.claim(target_id, self.role, start)
        target = mission.graph.target(target_id)
        inspected = mission.pursue(target) and target.inspected
        claims.release(target_id, self.clock)
        if inspected:
            self.inspected.append(target_id)
        return Activity(self.role, "inspect" if inspected else "skip", start, self.clock, target_id)

    @property
    def hop_cap_reached(self) -> bool:
        """Whether the team's frontier hops (both robots', one cap) are spent."""
        partner_hops = 0 if self.partner is None else self.partner.hops
        return self.hops + partner_hops >= self.mission.config.exploration.frontier_max_hops

    def _hop(self, keep: Callable[[np.ndarray], bool] | None = None) -> Hop:
        """One frontier hop and survey (among the goals ``keep`` accepts): ``"hopped"``;
        ``"missed"`` when the frontiers tried could not be reached (they are spent for this
        robot, and the next hop tries others); ``"none left"`` when none was left to try."""
        exploration = self.mission.exploration
        spent = len(exploration.spent_frontiers)
        if self.mission.explore(keep):
            self.hops += 1
            return "hopped"
        return "missed" if len(exploration.spent_frontiers) > spent else "none left"

    def _nearer_me(self, point: np.ndarray) -> bool:
        """Whether ``point`` is nearer this robot than the partner (where the partner is at
        its own clock): the partner's side of the bisector is the partner's to work."""
        if self.partner is None:
            return True
        here, there = self.mission.platform.position, self.partner.mission.platform.position
        return bool(np.linalg.norm(point - here) < np.linalg.norm(point - there))

    def _wait(self, start: float) -> Activity:
        """Nothing to do: stand still until the partner's clock if it is ahead (it may find
        or free a target, or leave frontiers, meanwhile), else stop."""
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
    """The explorer: the first survey, then per step a free target nearer it than the
    inspector (by eq (6)) or else one frontier hop (and survey), until exploration is done;
    then any free target by eq (6), like the inspector."""

    role = "explorer"

    def __init__(self, mission: XFlie) -> None:
        super().__init__(mission)
        #: Why exploration ended ("" while it runs).
        self.explored = ""

    @property
    def exploring(self) -> bool:
        return not (self.done or self.explored)

    def step(self) -> Activity:
        mission, start = self.mission, self.clock
        if not self.started:
            self.started = True
            mission.begin()
            return Activity(self.role, "survey", start, self.clock)
        if self.explored:
            return self.inspect_next(start)
        if mission.time_left > MIN_INSPECTION_S:
            choice = self._select(start, also_taken=self._nearer_the_partner())
            if choice is not None:
                return self._pursue(choice.target_id, start)
        if mission.time_left <= 0:
            self._stop("time budget spent")
        elif self.hop_cap_reached:
            self.explored = "frontier hop cap reached"
        elif self._hop() == "none left":  # a miss leaves the frontiers farther away to try
            self.explored = "no frontier left"
        return Activity(self.role, "explore", start, self.clock)

    def _nearer_the_partner(self) -> set[str]:
        """Uninspected targets no nearer this robot than the partner: the partner's to take
        while this one explores."""
        return {
            t.id
            for t in self.mission.graph.targets(TargetStatus.DETECTED)
            if not self._nearer_me(t.position)
        }

    def _stop(self, reason: str) -> None:
        self.stop_reason = f"{self.explored}, then {reason}" if self.explored else reason


class Inspector(TeamRobot):
    """The inspector: the next free target by eq (6); with none free, a frontier hop (and
    survey) on its own side of the explorer, or one the explorer spent, while the explorer
    explores (anywhere once it has stopped); with no frontier left for it either, it waits
    for the explorer."""

    role = "inspector"

    def step(self) -> Activity:
        if not self.started:  # a first LiDAR scan where it starts, as the explorer takes
            self.started = True
            self.mission.navigator.sense_lidar()
        return self.inspect_next(self.clock)

    def _when_none_free(self, start: float) -> Activity | None:
        """A frontier hop by :meth:`_may_explore` while the explorer explores (anywhere once
        it has stopped); None when no such frontier is left, or the hop cap is spent."""
        if self.hop_cap_reached:
            return None
        partner = self.partner
        exploring = partner is not None and partner.exploring
        hop = self._hop(self._may_explore if exploring else None)
        if hop == "hopped" or self.clock > start:  # frontiers tried and missed cost time too
            return Activity(self.role, "explore", start, self.clock)
        return None

    def _may_explore(self, goal: np.ndarray) -> bool:
        """While the explorer explores: a frontier nearer this robot than the explorer, or
        one the explorer has spent (it tried it and will not again)."""
        assert self.partner is not None  # only asked while the partner explores
        return self._nearer_me(goal) or self.partner.mission.exploration.is_spent(goal)


class Team:
    """An explorer and an inspector on one graph, interleaved by their clocks.

    Args:
        explorer: the explorer's mission (it explores, and inspects as described above).
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
