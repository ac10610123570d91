"""Which robot has taken which target, in simulated time, when robots share one 3DLSG.

Beyond 000 (after its Sec IX). A robot that selects a target by eq (6) claims it; until the
claim is released (the target inspected, or given up), no other robot may select it. A claim
is a time interval on the claimant's clock, and a released claim still holds for a robot whose
clock is earlier than the release: robots are simulated one whole step at a time, so the other
robot may ask about a moment inside the claimant's step, when the target was still taken.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from seminspect.core.errors import InvalidInputError


@dataclass(frozen=True)
class Claim:
    """One robot's hold on one target, from ``since`` until ``until`` (None: still held)."""

    target: str
    robot: str
    since: float
    until: float | None = None


class TargetClaims:
    """The claims on a graph's targets, and every claim ever made (for checking afterwards)."""

    def __init__(self) -> None:
        self._latest: dict[str, Claim] = {}
        #: Every claim in the order it was made, released ones with their release time.
        self.history: list[Claim] = []

    def taken_from(self, robot: str, time: float) -> set[str]:
        """Targets another robot holds at ``time``: ``robot`` must not select them.

        An open claim holds whatever the time; a released one until its release.
        """
        return {
            c.target
            for c in self._latest.values()
            if c.robot != robot and (c.until is None or time < c.until)
        }

    def claim(self, target: str, robot: str, time: float) -> Claim:
        """``robot`` takes ``target`` at ``time``; an error if another robot holds it then."""
        if target in self.taken_from(robot, time):
            holder = self._latest[target].robot
            raise InvalidInputError(f"target {target} is claimed by {holder} at t={time:.1f} s")
        claim = Claim(target, robot, time)
        self._latest[target] = claim
        self.history.append(claim)
        return claim

    def release(self, target: str, time: float) -> Claim:
        """End the open claim on ``target`` at ``time`` (inspected, or given up)."""
        claim = self._latest.get(target)
        if claim is None or claim.until is not None:
            raise InvalidInputError(f"target {target} is not claimed")
        released = replace(claim, until=time)
        self._latest[target] = released
        self.history[self.history.index(claim)] = released
        return released
