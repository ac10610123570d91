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
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

_TINY = 1e-12


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
    return float(np.sum(px[:, None] * py_x * np.log2(ratio)))


def merge_cost(pi: float, pj: float, yi: NDArray[np.float64], yj: NDArray[np.float64]) -> float:
    """Information lost by merging two clusters: ``(p_i + p_j) · JS_π``."""
    total = pi + pj
    wi, wj = pi / total, pj / total
    js = _entropy(wi * yi + wj * yj) - wi * _entropy(yi) - wj * _entropy(yj)
    return total * max(js, 0.0)


def agglomerate(
    py_x: NDArray[np.float64], links: Iterable[tuple[int, int]], delta: float
) -> RegionClusters:
    """Greedy connectivity-constrained AIB over primitives with rows ``p(y|x)``."""
    n = py_x.shape[0]
    px = np.full(n, 1.0 / n) if n else np.zeros(0)
    information = mutual_information(px, py_x) if n else 0.0
    weight = {i: float(px[i]) for i in range(n)}
    mix = {i: py_x[i].copy() for i in range(n)}
    parent = list(range(n))
    neighbours: dict[int, set[int]] = {i: set() for i in range(n)}
    for a, b in links:
        if a != b:
            neighbours[a].add(b)
            neighbours[b].add(a)
    version = dict.fromkeys(range(n), 0)
    heap = []
    for a in range(n):
        for b in neighbours[a]:
            if a < b:
                heap.append((merge_cost(weight[a], weight[b], mix[a], mix[b]), a, b, 0, 0))
    heapq.heapify(heap)
    budget = delta * information
    while heap:
        cost, a, b, va, vb = heapq.heappop(heap)
        if version.get(a) != va or version.get(b) != vb:
            continue  # one side has merged since this entry was pushed
        if cost > budget:
            break
        total = weight[a] + weight[b]
        mix[a] = (weight[a] * mix[a] + weight[b] * mix[b]) / total
        weight[a] = total
        parent[b] = a
        for other in neighbours.pop(b) - {a}:
            neighbours[other].discard(b)
            neighbours[other].add(a)
            neighbours[a].add(other)
        neighbours[a].discard(b)
        del weight[b], mix[b], version[b]
        version[a] += 1
        for other in neighbours[a]:
            lo, hi = min(a, other), max(a, other)
            entry = merge_cost(weight[lo], weight[hi], mix[lo], mix[hi])
            heapq.heappush(heap, (entry, lo, hi, version[lo], version[hi]))
    roots = [_root(parent, i) for i in range(n)]
    order = {root: k for k, root in enumerate(sorted(set(roots)))}
    assignment = np.array([order[r] for r in roots], dtype=np.int64)
    distributions = np.array([mix[r] for r in sorted(order)]).reshape(len(order), py_x.shape[1])
    cluster_weight = np.array([weight[r] for r in sorted(order)])
    retained = mutual_information(cluster_weight, distributions) if n else 0.0
    return RegionClusters(assignment, distributions, information, retained)


def _root(parent: list[int], i: int) -> int:
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i
