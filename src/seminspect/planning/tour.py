"""The visiting tour ``Z*`` over a task's view poses: simulated-annealing TSP (002 Sec III-C).

The robot stands at the start of the tour and need not return, so the tour is an open path
with a fixed first point. :func:`annealed_tour` is the paper's solver (simulated annealing with
2-opt moves, 002 ref [11]); :func:`reference_tour` solves the same problem with LKH (through
the optional ``elkai`` package) to measure how far the annealed tour is from the optimum.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError, SeminspectError
from seminspect.geometry.transforms import as_point, as_points

#: Annealing moves per view pose; cooling runs from the mean edge length down to 1e-3 of it.
MOVES_PER_POINT = 4000
FINAL_TEMPERATURE_RATIO = 1e-3


@dataclass(frozen=True)
class Tour:
    """A visiting order (indices into the view poses) and its length from the start [m]."""

    order: NDArray[np.int64]
    length: float


def distance_matrix(start: ArrayLike, points: ArrayLike) -> NDArray[np.float64]:
    """Euclidean distances between ``start`` (index 0) and the points (indices 1..n)."""
    nodes = np.vstack([as_point(start, "tour start"), as_points(points, "view poses")])
    return np.linalg.norm(nodes[:, None, :] - nodes[None, :, :], axis=-1)


def open_tour_length(distances: NDArray[np.float64], order: ArrayLike) -> float:
    """Length of start -> points in ``order`` (0-based point indices) over ``distances``."""
    nodes = np.concatenate([[0], np.asarray(order, dtype=np.int64) + 1])
    return float(distances[nodes[:-1], nodes[1:]].sum())


def _nearest_neighbour_order(distances: NDArray[np.float64]) -> NDArray[np.int64]:
    left = list(range(1, len(distances)))
    order, here = [], 0
    while left:
        here = min(left, key=lambda j: distances[here, j])
        left.remove(here)
        order.append(here)
    return np.asarray(order, dtype=np.int64)


@numba.njit(cache=True)
def _anneal(  # noqa: PLR0917  # pragma: no cover - compiled
    distances: NDArray[np.float64],
    path: NDArray[np.int64],
    picks: NDArray[np.int64],
    accept: NDArray[np.float64],
    temperatures: NDArray[np.float64],
    length: float,
) -> NDArray[np.int64]:
    """2-opt simulated annealing of ``path`` (node 0 fixed first, open end) of ``length``;
    returns the shortest path met."""
    n = path.shape[0]
    best = path.copy()
    best_length = length
    for move in range(picks.shape[0]):
        i, j = picks[move, 0], picks[move, 1]
        if i > j:
            i, j = j, i
        if i in (j, 0):
            continue
        a, b, c = path[i - 1], path[i], path[j]
        delta = distances[a, c] - distances[a, b]
        if j + 1 < n:
            d = path[j + 1]
            delta += distances[b, d] - distances[c, d]
        if delta <= 0 or accept[move] < math.exp(-delta / temperatures[move]):
            path[i : j + 1] = path[i : j + 1][::-1].copy()
            length += delta
            if length < best_length - 1e-12:
                best_length = length
                best[:] = path
    return best


def annealed_tour(start: ArrayLike, points: ArrayLike, rng: np.random.Generator) -> Tour:
    """SA-TSP (002 Sec III-C): an open tour from ``start`` through every point.

    Starts from the nearest-neighbour order and anneals it with 2-opt reversals, geometric
    cooling and Metropolis acceptance; every random draw comes from ``rng``.
    """
    distances = distance_matrix(start, points)
    n = len(distances) - 1
    first = _nearest_neighbour_order(distances)
    if n < 3:
        return _best_small(distances)
    moves = MOVES_PER_POINT * n
    picks = rng.integers(1, n + 1, size=(moves, 2))
    accept = rng.random(moves)
    length = open_tour_length(distances, first - 1)
    temperatures = (length / n) * FINAL_TEMPERATURE_RATIO ** (np.arange(moves) / (moves - 1))
    path = np.concatenate([[0], first])
    best = _anneal(distances, path, picks, accept, temperatures, length)
    order = best[1:] - 1
    return Tour(order, open_tour_length(distances, order))


def _best_small(distances: NDArray[np.float64]) -> Tour:
    """One or two points: try both orders."""
    n = len(distances) - 1
    orders = [np.arange(n), np.arange(n)[::-1]]
    best = min(orders, key=lambda o: open_tour_length(distances, o))
    return Tour(best.astype(np.int64), open_tour_length(distances, best))


def reference_tour(start: ArrayLike, points: ArrayLike, runs: int = 10) -> Tour:
    """The same open tour solved by LKH (``elkai``), the yardstick for :func:`annealed_tour`.

    A dummy node closes the path into a cycle, which LKH solves: it is 0 from the start and a
    constant ``B`` (longer than any tour) from every other node, so an optimal cycle runs
    start -> ... -> last -> dummy -> start and costs the open path plus ``B``. Distances are
    rounded to millimetres because LKH works on integers.
    """
    try:
        import elkai  # noqa: PLC0415 - optional extra, loaded when used
    except ImportError:
        raise SeminspectError(
            "the reference TSP solver needs elkai: pip install 'seminspect[tsp]'"
        ) from None
    distances = distance_matrix(start, points)
    n = len(distances) - 1
    if n < 3:
        return _best_small(distances)
    closed = np.zeros((n + 2, n + 2))
    closed[: n + 1, : n + 1] = distances
    closed[n + 1, 1:] = closed[1:, n + 1] = (n + 1) * distances.max() + 1.0
    closed[n + 1, n + 1] = 0.0
    cycle = elkai.DistanceMatrix(np.rint(closed * 1000).astype(int).tolist()).solve_tsp(runs)
    return Tour(*_open_from_cycle(cycle, n, distances))


def _open_from_cycle(cycle: list[int], n: int, distances: NDArray[np.float64]):
    """Cut a cycle through start (0), points (1..n) and the dummy (n+1) into an open path."""
    ring = list(cycle[:-1]) if cycle[0] == cycle[-1] else list(cycle)
    at = ring.index(0)
    ring = ring[at:] + ring[:at]
    if ring[-1] != n + 1:  # the dummy follows the start: walk the cycle the other way
        ring = [0, *ring[1:][::-1]]
    if ring[-1] != n + 1:
        raise InvalidInputError("the reference solver returned a tour without its dummy node")
    order = np.asarray(ring[1:-1], dtype=np.int64) - 1
    return order, open_tour_length(distances, order)
