"""The reward terms of 004 eq (6), R = f_t + v_t + p_t, as plain functions over rows of rooms.

The environment gathers what each term needs (the faces in view, the local visit total N_t,
the ego map's cells near the robot); these functions are the equations.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray


def face_scores(
    distance: NDArray[np.float64],
    best: NDArray[np.float64],
    d_ref: float,
    alpha: float,
    beta: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """004 eqs (7)-(8): per-face inspection scores n_f and the updated best distances d_f.

    ``distance`` holds this step's mean camera-face distance (nan for faces not in view);
    ``best`` the stored d_f (inf before the first view). f_t (eq (9)) is a row's sum.
    """
    seen = np.isfinite(distance)
    closer = seen & (np.abs(np.where(seen, distance, 0.0) - d_ref) < np.abs(best - d_ref))
    scores = np.where(
        closer, alpha * np.exp(-beta * (np.where(seen, distance, 0.0) - d_ref) ** 2), 0.0
    )
    return scores, np.where(scores > 0, distance, best)


def semantic_search_reward(visits: NDArray, gamma: float, delta: float) -> NDArray[np.float64]:
    """004 eq (10): v_t = gamma exp(-delta N_t)."""
    return gamma * np.exp(-delta * np.asarray(visits, dtype=np.float64))


def collision_penalty(near_occupancy: NDArray) -> NDArray[np.float64]:
    """p_t of 004 eq (6): -1 for a row with any occupied cell of m^o within d_coll, else 0.

    ``near_occupancy`` is ``(rows, cells)``: each row's m^o cells within d_coll of the robot.
    """
    return np.where(np.asarray(near_occupancy).any(axis=1), -1.0, 0.0)
