"""The graph columns of 000 Table 3: nodes and edges per layer, unified, and "reconciled".

See docs/scene-graph.md for how the reconciled share was read off the paper's tables.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from seminspect.graphs.lsg.model import LocalGraph


@dataclass(frozen=True, slots=True)
class LayerPopulation:
    """Nodes and edges summed over the local graphs of one layer."""

    nodes: int
    edges: int

    def __str__(self) -> str:
        return f"{self.nodes}/{self.edges}"

    @classmethod
    def summed(cls, graphs: Iterable[LocalGraph]) -> LayerPopulation:
        """The population of a layer made of ``graphs``, parents counted in each."""
        counts = [g.population() for g in graphs]
        return cls(sum(c[0] for c in counts), sum(c[1] for c in counts))


@dataclass(frozen=True, slots=True)
class PopulationStats:
    """The graph columns of 000 Table 3.

    ``reconciled_pct`` is the share of local-graph node registrations that the union merged into
    a node already present: ``100 * (sum of local nodes - unified nodes) / sum of local nodes``.
    A node is counted once per local graph it belongs to (a level is a child in its target's
    Level graph and the parent of its Pose graph), so the union reconciles exactly the parents.
    """

    target: LayerPopulation
    level: LayerPopulation
    pose: LayerPopulation
    feature: LayerPopulation
    unified: LayerPopulation
    targets_detected: int
    targets_inspected: int

    @property
    def total(self) -> LayerPopulation:
        layers = (self.target, self.level, self.pose, self.feature)
        return LayerPopulation(sum(p.nodes for p in layers), sum(p.edges for p in layers))

    @property
    def reconciled_pct(self) -> float:
        total = self.total.nodes
        return 100.0 * (total - self.unified.nodes) / total if total else 0.0
