"""The reward terms of 004 eq (6), R = f_t + v_t + p_t, as plain functions over rows of rooms.

The environment gathers what each term needs (the faces in view, the local visit total N_t,
the ego map's cells near the robot); these functions are the equations. Each term has the
paper's form and the form policy v1 was trained on (:meth:`EnvConfig.legacy`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray


def distance_score(distance: NDArray, d_ref: float, beta: float) -> NDArray[np.float64]:
    """s(d) = exp(-beta (d - d_ref)^2), the distance weight of 004 eq (7); s(inf) = 0."""
    d = np.asarray(distance, dtype=np.float64)
    finite = np.isfinite(d)
    return np.where(finite, np.exp(-beta * (np.where(finite, d, d_ref) - d_ref) ** 2), 0.0)


def _closer(distance: NDArray[np.float64], best: NDArray[np.float64], d_ref: float) -> NDArray:
    """Faces seen this step strictly closer to d_ref than their stored d_f (eq (7)'s test)."""
    seen = np.isfinite(distance)
    return seen & (np.abs(np.where(seen, distance, 0.0) - d_ref) < np.abs(best - d_ref))


def face_scores(
    distance: NDArray[np.float64],
    best: NDArray[np.float64],
    d_ref: float,
    alpha: float,
    beta: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """004 eqs (7)-(8): per-face inspection scores n_f and the updated best distances d_f.

    The repaid form (policy v1): alpha s(d) again at every gain toward d_ref. ``distance``
    holds this step's mean camera-face distance (nan for faces not in view); ``best`` the
    stored d_f (inf before the first view). f_t (eq (9)) is a row's sum.
    """
    closer = _closer(distance, best, d_ref)
    scores = np.where(closer, alpha * distance_score(distance, d_ref, beta), 0.0)
    return scores, np.where(scores > 0, distance, best)


def updated_best(
    distance: NDArray[np.float64], best: NDArray[np.float64], d_ref: float
) -> NDArray[np.float64]:
    """004 eq (8): d_f becomes this step's mean distance d where d is closer to d_ref."""
    return np.where(_closer(distance, best, d_ref), distance, best)


def inspected_fraction(best: NDArray[np.float64], d_ref: float, beta: float) -> NDArray[np.float64]:
    """f_t of the fraction form: (1/N_f) sum_f s(d_f), one value in [0, 1] per row.

    004 Sec III-C: "f_t in [0, 1] is the fraction of the inspected faces ... seen with the
    camera sensor until time t, weighted by observation distance", "provided to the agent at
    every action step": the fraction so far is paid at every step, so covering early pays more
    and a crash forfeits the rest of the episode's stream.
    """
    return distance_score(best, d_ref, beta).mean(axis=1)


def shaped_fraction(
    fraction: NDArray[np.float64], previous: NDArray[np.float64], discount: float
) -> NDArray[np.float64]:
    """The stream f_t paid through the potential Phi = f / (1 - discount): the step's term
    f_t + discount Phi_t - Phi_{t-1} = (f_t - f_{t-1}) / (1 - discount).

    Potential-based shaping leaves the best policy under ``discount`` unchanged (Ng, Harada
    and Russell 1999) and pays a face when it is seen, not spread over the rest of the episode.
    """
    return (fraction - previous) / (1.0 - discount)


def shaping_forfeit(fraction: NDArray[np.float64], discount: float) -> NDArray[np.float64]:
    """What a crash costs beyond its step's shaped term: a terminal state's potential is 0, so
    the step pays f_t - Phi_{t-1}, which is :func:`shaped_fraction` less discount Phi_t."""
    return discount * fraction / (1.0 - discount)


def semantic_search_reward(visits: NDArray, gamma: float, delta: float) -> NDArray[np.float64]:
    """004 eq (10): v_t = gamma exp(-delta N_t)."""
    return gamma * np.exp(-delta * np.asarray(visits, dtype=np.float64))


def collision_penalty(near_occupancy: NDArray) -> NDArray[np.float64]:
    """p_t of 004 eq (6): -1 for a row with any occupied cell of m^o within d_coll, else 0.

    ``near_occupancy`` is ``(rows, cells)``: each row's m^o cells within d_coll of the robot
    (occupied reads 1; free 0 and unknown 0.5 do not count).
    """
    return np.where((np.asarray(near_occupancy) >= 1.0).any(axis=1), -1.0, 0.0)


def graded_penalty(
    near_occupancy: NDArray, cell_distance: NDArray, d_coll: float, reach: float
) -> NDArray[np.float64]:
    """p_t graded: -1 with an occupied m^o cell within d_coll, rising linearly to 0 at reach.

    ``near_occupancy`` is ``(rows, cells)``, the m^o cells within ``reach``; ``cell_distance``
    their centres' distances from the robot. The nearest occupied cell decides.
    """
    occupied = np.asarray(near_occupancy) >= 1.0
    nearest = np.where(occupied, cell_distance, np.inf).min(axis=1, initial=np.inf)
    span = max(reach - d_coll, 1e-9)  # reach == d_coll: a step at d_coll
    return np.where(nearest <= d_coll, -1.0, -np.clip((reach - nearest) / span, 0.0, 1.0))


def contact_penalty(
    near_occupancy: NDArray,
    cell_offsets: NDArray,
    velocity: NDArray,
    robot_radius: float,
    horizon: float,
) -> NDArray[np.float64]:
    """A penalty for closing on an occupied m^o cell: -(1 - t_c / horizon), clipped to [-1, 0].

    t_c is the time to contact at the current velocity: the cell's distance less the robot
    radius over the speed toward it, the soonest of the row's occupied cells. The graded
    penalty reads distance only, so at 1.3 m/s (the measured crash speed) its 0.3 m zone is
    crossed in 2-3 steps; this one grows with speed and falls to 0 when moving away.
    ``near_occupancy`` is ``(rows, cells)``; ``cell_offsets`` the cells' ``(cells, 3)``
    offsets from the robot and ``velocity`` the rows' ``(rows, 3)``, in one frame.
    """
    rows, cells = np.nonzero(np.asarray(near_occupancy) >= 1.0)  # few: walk those only
    offsets = np.asarray(cell_offsets, dtype=np.float64)[cells]
    distance = np.linalg.norm(offsets, axis=1)
    along = np.einsum("ij,ij->i", np.asarray(velocity, dtype=np.float64)[rows], offsets)
    closing = along / np.maximum(distance, 1e-9)  # speed toward each occupied cell
    gap = np.maximum(distance - robot_radius, 0.0)
    time_to_contact = np.where(closing > 0.0, gap / np.where(closing > 0.0, closing, 1.0), np.inf)
    soonest = np.full(len(velocity), np.inf)
    np.minimum.at(soonest, rows, time_to_contact)
    return -np.clip(1.0 - soonest / horizon, 0.0, 1.0)
