"""Scoring a mission's graph against ground truth (000 Tables 3 and 6).

Graph targets are matched one-to-one to true objects of the same class by minimum total
horizontal distance (the Hungarian method), ignoring pairs farther apart than a gate. Then:

* **detected %**: true objects matched by any target node, over all true objects;
* **inspected %**: matched targets that were inspected, over matched targets (000 Table 3
  reports inspection as a share of detections);
* **localisation RMSE**: root mean square distance between inspected targets and their true
  centres, horizontal (what the containment-polygon refinement corrects) and 3D (000 Table 6);
  a mission that never inspects is scored on every target it found (:func:`scored_matches`);
* **false targets**: target nodes matched to no true object.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

from seminspect.graphs.lsg.model import TargetNode

#: A target node farther than this from a true object's centre is not a detection of it.
DEFAULT_GATE_M = 4.0


@dataclass(frozen=True, slots=True)
class TruthTarget:
    """A true object: name, class and centre (the world's ground truth)."""

    name: str
    label: str
    centre: NDArray[np.float64]


@dataclass(frozen=True, slots=True)
class Match:
    target_id: str
    truth: str
    horizontal_error: float
    error_3d: float
    inspected: bool


@dataclass(frozen=True, slots=True)
class TargetScore:
    """How well a graph's Target layer matches the world."""

    matches: tuple[Match, ...]
    truths: int
    targets: int

    @property
    def detected_pct(self) -> float:
        return 100.0 * len(self.matches) / self.truths if self.truths else 0.0

    @property
    def inspected_pct(self) -> float:
        if not self.matches:
            return 0.0
        return 100.0 * sum(m.inspected for m in self.matches) / len(self.matches)

    @property
    def false_targets(self) -> int:
        return self.targets - len(self.matches)

    def rmse(self, horizontal: bool = True) -> float:
        """RMSE over inspected, matched targets (NaN when none)."""
        return localisation_rmse([m for m in self.matches if m.inspected], horizontal)


def localisation_rmse(matches: Sequence[Match], horizontal: bool = True) -> float:
    """Root mean square localisation error of ``matches`` [m] (NaN when there are none)."""
    errors = [m.horizontal_error if horizontal else m.error_3d for m in matches]
    return math.sqrt(float(np.mean(np.square(errors)))) if errors else math.nan


def scored_matches(matches: Sequence[Match], inspecting: bool) -> list[Match]:
    """The targets 000 Table 6's coverage and RMSE are taken over: the inspected ones, or for
    a mission that never inspects (an explorer) every target it found; the paper scores
    GBPlanner2.0 on the targets it observed (000 Sec VII-D)."""
    return [m for m in matches if m.inspected or not inspecting]


def score_targets(
    targets: Sequence[TargetNode], truths: Sequence[TruthTarget], gate: float = DEFAULT_GATE_M
) -> TargetScore:
    """Match target nodes to true objects and score them (see the module docstring)."""
    if not targets or not truths:
        return TargetScore((), len(truths), len(targets))
    t_xy = np.array([t.position[:2] for t in targets])
    g_xy = np.array([g.centre[:2] for g in truths])
    cost = np.linalg.norm(t_xy[:, None, :] - g_xy[None, :, :], axis=2)
    same_class = np.array([[t.label == g.label for g in truths] for t in targets])
    blocked = (cost > gate) | ~same_class
    rows, cols = linear_sum_assignment(np.where(blocked, 1e6, cost))
    matches = []
    for r, c in zip(rows, cols, strict=True):
        if blocked[r, c]:
            continue
        target, truth = targets[r], truths[c]
        matches.append(
            Match(
                target.id,
                truth.name,
                float(cost[r, c]),
                float(np.linalg.norm(target.position - truth.centre)),
                target.inspected,
            )
        )
    return TargetScore(tuple(matches), len(truths), len(targets))
