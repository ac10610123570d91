"""Layer 4: task-driven regions by agglomerative information bottleneck (001 Sec III-B.4).

001 leaves regions to future work and names Clio's AIB [19]. seminspect implements it in that
spirit (see ``docs/terrain.md``):

- primitives ``x`` are the place and object nodes, equally likely, ``p(x) = 1/n``;
- ``y`` ranges over the task prompts plus a *null task*; ``p(y|x)`` puts the primitive's mean
  similarity to each prompt (clipped at 0) and the null task's fixed similarity θ side by side,
  keeps the ``top_k`` largest, and normalises; a primitive whose best match is the null task is
  entirely "null";
- starting from one cluster per primitive, the two *adjacent* clusters (linked in the graph)
  whose merge loses the least information ``δI = (p_i + p_j) · JS_π(p(y|c_i), p(y|c_j))`` are
  merged (Slonim and Tishby's AIB with a connectivity constraint), until the cheapest merge would
  lose more than ``delta · I(X;Y)``.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

_TINY = 1e-12
#: A merge losing at most this many bits loses nothing: identical task mixes cost a few 1e-17
#: of rounding, which must not stop them where I(X;Y) = 0 and the budget is 0 (one task only).
FREE_MERGE = 1e-12


@dataclass(frozen=True)
class RegionClusters:
    """The result of the bottleneck: a cluster per primitive and each cluster's task mix.

    Attributes:
        assignment: ``(n,)`` cluster index of every primitive.
        distributions: ``(R, 1 + P)`` ``p(y|cluster)``; column 0 is the null task.
        information: ``I(X;Y)`` of the primitives, bits.
        retained: ``I(C;Y)`` of the clusters, bits.
    """

    assignment: NDArray[np.int64]
    distributions: NDArray[np.float64]
    information: float
    retained: float


def task_distributions(
    similarity: NDArray[np.floating], null_similarity: float, top_k: int
) -> NDArray[np.float64]:
    """``p(y|x)`` of every primitive from its similarity to each prompt (Clio's construction)."""
    scores = np.column_stack(
        [np.full(similarity.shape[0], null_similarity), np.clip(similarity, 0.0, None)]
    ).astype(np.float64)
    k = min(top_k, scores.shape[1])
    kept = np.zeros_like(scores)
    top = np.argpartition(-scores, k - 1, axis=1)[:, :k]
    rows = np.arange(scores.shape[0])[:, None]
    kept[rows, top] = scores[rows, top]
    kept += _TINY
    null_best = np.argmax(scores, axis=1) == 0
    kept[null_best] = _TINY
    kept[null_best, 0] = 1.0
    return kept / kept.sum(axis=1, keepdims=True)


def _entropy(p: NDArray[np.float64]) -> float:
    p = p[p > 0]
    return float(-(p * np.log2(p)).sum())


def mutual_information(px: NDArray[np.float64], py_x: NDArray[np.float64]) -> float:
    """``I(X;Y)`` in bits for ``p(x)`` and rows ``p(y|x)``."""
    py = px @ py_x
    ratio = np.where(py_x > 0, py_x / np.where(py > 0, py, 1.0), 1.0)
    # rounding leaves a few -1e-15 where every row is the same; information is never negative
    return max(float(np.sum(px[:, None] * py_x * np.log2(ratio))), 0.0)


@dataclass
class _Clusters:
    """The bottleneck's working state: each live cluster's weight, task mix and x-y box."""

    weight: dict[int, float]
    mix: dict[int, NDArray[np.float64]]
    low: dict[int, NDArray[np.float64]]
    high: dict[int, NDArray[np.float64]]
    version: dict[int, int]
    entropy: dict[int, float]  # H(Y|c) of each cluster, kept to price merges three times faster

    def entry(self, a: int, b: int) -> tuple[float, float, int, int, int, int]:
        """Heap key of merging ``a`` and ``b``: the information lost, ``(p_i + p_j) · JS_π``
        (Slonim and Tishby; free below the tolerance), then the merged size."""
        lo, hi = min(a, b), max(a, b)
        total = self.weight[lo] + self.weight[hi]
        wi, wj = self.weight[lo] / total, self.weight[hi] / total
        mixed = _entropy(wi * self.mix[lo] + wj * self.mix[hi])
        cost = total * max(mixed - wi * self.entropy[lo] - wj * self.entropy[hi], 0.0)
        free = 0.0 if cost <= FREE_MERGE else cost
        return (free, total, lo, hi, self.version[lo], self.version[hi])

    def extent(self, a: int, b: int) -> float:
        """Diagonal of the x-y box of the two clusters' members together, metres."""
        span = np.maximum(self.high[a], self.high[b]) - np.minimum(self.low[a], self.low[b])
        return float(np.hypot(span[0], span[1]))

    def merge(self, a: int, b: int) -> None:
        total = self.weight[a] + self.weight[b]
        self.mix[a] = (self.weight[a] * self.mix[a] + self.weight[b] * self.mix[b]) / total
        self.weight[a] = total
        self.low[a] = np.minimum(self.low[a], self.low[b])
        self.high[a] = np.maximum(self.high[a], self.high[b])
        self.entropy[a] = _entropy(self.mix[a])
        del self.weight[b], self.mix[b], self.low[b], self.high[b], self.version[b]
        del self.entropy[b]
        self.version[a] += 1


def _neighbours(n: int, links: Iterable[tuple[int, int]]) -> dict[int, set[int]]:
    neighbours: dict[int, set[int]] = {i: set() for i in range(n)}
    for a, b in links:
        if a != b:
            neighbours[a].add(b)
            neighbours[b].add(a)
    return neighbours


def agglomerate(
    py_x: NDArray[np.float64],
    links: Iterable[tuple[int, int]],
    delta: float,
    positions: NDArray[np.floating] | None = None,
    max_extent: float = math.inf,
) -> RegionClusters:
    """Greedy connectivity-constrained AIB over primitives with rows ``p(y|x)``.

    With ``positions`` (``(n, 2+)``, x-y used), a merge whose members would span more than
    ``max_extent`` metres (their x-y box's diagonal) is skipped, so a region is spatially
    bounded even where every primitive serves the same task and the bottleneck sees nothing to
    keep apart. Merges that lose no information (at most :data:`FREE_MERGE` bits) go first and
    smallest first, so such regions grow evenly rather than as one chain.
    """
    n = py_x.shape[0]
    px = np.full(n, 1.0 / n) if n else np.zeros(0)
    information = mutual_information(px, py_x) if n else 0.0
    xy = np.zeros((n, 2)) if positions is None else np.asarray(positions, np.float64)[:, :2]
    state = _Clusters(
        weight={i: float(px[i]) for i in range(n)},
        mix={i: py_x[i].copy() for i in range(n)},
        low={i: xy[i].copy() for i in range(n)},
        high={i: xy[i].copy() for i in range(n)},
        version=dict.fromkeys(range(n), 0),
        entropy={i: _entropy(py_x[i]) for i in range(n)},
    )
    parent = list(range(n))
    neighbours = _neighbours(n, links)
    heap = [state.entry(a, b) for a in range(n) for b in neighbours[a] if a < b]
    heapq.heapify(heap)
    budget = delta * information
    while heap:
        cost, _, a, b, va, vb = heapq.heappop(heap)
        if state.version.get(a) != va or state.version.get(b) != vb:
            continue  # one side has merged since this entry was pushed
        if cost > budget:
            break
        if state.extent(a, b) > max_extent:
            continue  # boxes only grow: this pair stays too large
        state.merge(a, b)
        parent[b] = a
        for other in neighbours.pop(b) - {a}:
            neighbours[other].discard(b)
            neighbours[other].add(a)
            neighbours[a].add(other)
        neighbours[a].discard(b)
        for other in neighbours[a]:
            heapq.heappush(heap, state.entry(a, other))
    return _result(parent, state, information, py_x.shape[1])


def _result(parent: list[int], state: _Clusters, information: float, tasks: int) -> RegionClusters:
    roots = [_root(parent, i) for i in range(len(parent))]
    order = {root: k for k, root in enumerate(sorted(set(roots)))}
    assignment = np.array([order[r] for r in roots], dtype=np.int64)
    distributions = np.array([state.mix[r] for r in sorted(order)]).reshape(len(order), tasks)
    cluster_weight = np.array([state.weight[r] for r in sorted(order)])
    retained = mutual_information(cluster_weight, distributions) if parent else 0.0
    return RegionClusters(assignment, distributions, information, retained)


def _root(parent: list[int], i: int) -> int:
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i
