"""The reward terms of 004 eq (6) by hand: f_t's face scores, v_t and p_t."""

import math

import numpy as np
import pytest

from seminspect.missions.learning.rewards import (
    collision_penalty,
    face_scores,
    semantic_search_reward,
)

D_REF, ALPHA, BETA = 1.5, 0.15, 1.0


def _scores(distance, best):
    return face_scores(np.array([distance]), np.array([best]), D_REF, ALPHA, BETA)


def test_a_face_first_seen_at_d_ref_scores_alpha():
    score, best = _scores(D_REF, np.inf)
    assert score[0] == pytest.approx(ALPHA)
    assert best[0] == D_REF


def test_a_farther_later_view_scores_nothing_and_keeps_d_f():
    score, best = _scores(D_REF + 1.0, D_REF)
    assert score[0] == 0.0 and best[0] == D_REF
    score, best = _scores(np.nan, D_REF)  # not in view this step
    assert score[0] == 0.0 and best[0] == D_REF


def test_a_view_closer_to_d_ref_scores_again_and_updates_d_f():
    score, best = _scores(D_REF + 0.5, D_REF + 1.0)
    assert score[0] == pytest.approx(ALPHA * math.exp(-BETA * 0.25))
    assert best[0] == D_REF + 0.5
    # equally far on the other side of d_ref is not closer: eq (7) needs strictly less
    score, _ = _scores(D_REF - 1.0, D_REF + 1.0)
    assert score[0] == 0.0


def test_semantic_search_reward_is_eq_10():
    reward = semantic_search_reward(np.array([0, 10, 100]), gamma=0.005, delta=0.02)
    np.testing.assert_allclose(reward, 0.005 * np.exp(-0.02 * np.array([0, 10, 100])))
    assert reward[0] == 0.005 and reward[2] < reward[1] < reward[0]


def test_the_collision_penalty_is_minus_one_for_any_occupied_near_cell():
    near = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 1.0]], dtype=np.float32)
    np.testing.assert_array_equal(collision_penalty(near), [0.0, -1.0, -1.0])
