"""Target selection by inspection utility, 000 eq (6).

``U(v_D) = S_p P(v_D) + S_a A(v_D) + S_n N(v_D)`` with

* ``P = 1 / ||x_k^p - p(v_D)||``: proximity of the robot;
* ``A = s^a / (I_w I_h)``: the mask area as a share of the image;
* ``N = 1 / d̄``: centrality, ``d̄`` being the mean distance to the other uninspected targets.

The paper leaves two cases undefined; both get finite values here:

* **the robot stands on a target** (distance 0, ``P`` infinite): distances are floored at the
  arrival radius ``ε`` (000 Table 1: 2 m), inside which a target counts as reached, so ``P`` is
  at most ``1 / ε``; ``d̄`` is floored the same way;
* **one uninspected target** (``|V_D| - 1 = 0``, ``d̄`` undefined): it has no neighbours to be
  central to, so ``N = 0``.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from seminspect.core.params import InspectionParams
from seminspect.geometry.transforms import as_point
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import TargetNode, TargetStatus


@dataclass(frozen=True, slots=True)
class UtilityTerms:
    """The terms of eq (6) for one candidate target."""

    target_id: str
    proximity: float
    area: float
    centrality: float
    utility: float


def utility_terms(
    robot_position: ArrayLike, candidates: Sequence[TargetNode], params: InspectionParams
) -> list[UtilityTerms]:
    """Eq (6) for every candidate (uninspected) target."""
    if not candidates:
        return []
    robot = as_point(robot_position, "robot position")
    positions = np.array([c.position for c in candidates])
    floor = params.epsilon
    proximity = 1.0 / np.maximum(np.linalg.norm(positions - robot, axis=1), floor)
    area = np.array([c.mask_area for c in candidates]) / params.image_area
    count = len(candidates)
    if count > 1:
        pairwise = np.linalg.norm(positions[:, None, :] - positions[None, :, :], axis=2)
        mean_distance = pairwise.sum(axis=1) / (count - 1)
        centrality = 1.0 / np.maximum(mean_distance, floor)
    else:
        centrality = np.zeros(1)
    utility = (
        params.utility_S_p * proximity + params.utility_S_a * area + params.utility_S_n * centrality
    )
    return [
        UtilityTerms(c.id, float(p), float(a), float(n), float(u))
        for c, p, a, n, u in zip(candidates, proximity, area, centrality, utility, strict=True)
    ]


def select_target(
    graph: LayeredSemanticGraph, exclude: Collection[str] = ()
) -> tuple[UtilityTerms | None, list[UtilityTerms]]:
    """``v_D* = argmax U(v_D)`` over the detected targets (ties: the earliest registered).

    Stores each candidate's utility on its node (the attribute ``U`` of 000 Sec IV-A) and
    returns the winner (None when nothing is left to inspect) with every candidate's terms.
    Targets in ``exclude`` (e.g. found unreachable) are not candidates.
    """
    candidates = [t for t in graph.targets(TargetStatus.DETECTED) if t.id not in exclude]
    terms = utility_terms(graph.robot.position, candidates, graph.params)
    for node, term in zip(candidates, terms, strict=True):
        node.utility = term.utility
    if not terms:
        return None, terms
    best = max(range(len(terms)), key=lambda i: (terms[i].utility, -i))
    return terms[best], terms
