"""The reward terms of 004 eq (6) by hand: f_t's face scores (repaid and fraction), its
shaping, v_t and p_t (binary, graded and by time to contact)."""

import math

import numpy as np
import pytest

from seminspect.missions.learning.rewards import (
    collision_penalty,
    contact_penalty,
    distance_score,
    face_scores,
    graded_penalty,
    inspected_fraction,
    semantic_search_reward,
    shaped_fraction,
    shaping_forfeit,
    updated_best,
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
    # unknown cells (0.5 in the three-state map) are not occupied
    assert collision_penalty(np.full((1, 3), 0.5, dtype=np.float32))[0] == 0.0


def test_the_graded_penalty_is_minus_one_within_d_coll_and_falls_linearly_to_reach():
    distance = np.array([0.1, 0.3, 0.4, 0.5, 0.6])  # the cells' distances from the robot
    rows = np.zeros((5, 5), dtype=np.float32)
    rows[np.arange(5), np.arange(5)] = 1.0  # row i: only cell i occupied
    penalty = graded_penalty(rows, distance, d_coll=0.3, reach=0.6)
    np.testing.assert_allclose(penalty, [-1.0, -1.0, -2.0 / 3.0, -1.0 / 3.0, 0.0], atol=1e-12)
    # the nearest occupied cell decides; unknown (0.5) and free cells do not count
    mixed = np.array([[0.5, 0.5, 1.0, 0.0, 1.0]], dtype=np.float32)
    assert graded_penalty(mixed, distance, 0.3, 0.6)[0] == pytest.approx(-2.0 / 3.0)
    assert graded_penalty(np.zeros((1, 5)), distance, 0.3, 0.6)[0] == 0.0
    # reach == d_coll: a step
    np.testing.assert_array_equal(graded_penalty(rows, distance, 0.3, 0.3), [-1, -1, 0, 0, 0])


def test_the_contact_penalty_grows_as_the_time_to_contact_falls_below_the_horizon():
    ahead, beside = [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]  # offsets of two cells, 1 m away
    cells = np.array([ahead, beside])
    occupied = np.array([[1.0, 0.0]])  # only the cell ahead
    radius, horizon = 0.2, 1.0  # 0.8 m of gap

    def penalty(velocity, occupancy=occupied):
        return contact_penalty(occupancy, cells, np.array([velocity]), radius, horizon)[0]

    assert penalty([1.6, 0.0, 0.0]) == pytest.approx(-0.5)  # contact in 0.5 s
    assert penalty([0.4, 0.0, 0.0]) == 0.0  # 2 s: beyond the horizon
    assert penalty([-1.0, 0.0, 0.0]) == 0.0  # moving away
    assert penalty([0.0, 1.6, 0.0]) == 0.0  # toward a free cell
    # the speed toward the cell counts, not the speed: 1.6 m/s at 60 degrees closes at 0.8
    assert penalty([0.8, 0.8 * math.sqrt(3.0), 0.0]) == pytest.approx(0.0, abs=1e-12)
    assert penalty([1.0e6, 0.0, 0.0]) == pytest.approx(-1.0)  # clipped at -1
    # unknown (0.5) does not count; the soonest of several occupied cells decides
    assert penalty([1.6, 0.0, 0.0], np.array([[0.5, 0.0]])) == 0.0
    both = np.array([[1.0, 1.0]])
    assert penalty([1.6, 3.2, 0.0], both) == pytest.approx(-0.75)  # beside: 0.25 s


def test_the_distance_score_is_eq_7s_weight_and_zero_for_never_seen():
    score = distance_score(np.array([D_REF, D_REF + 1.0, np.inf]), D_REF, BETA)
    np.testing.assert_allclose(score, [1.0, math.exp(-BETA), 0.0])


def test_the_fraction_form_pays_the_distance_weighted_fraction_so_far_at_every_step():
    """f_t = (1/N_f) sum_f s(d_f) with d_f kept by eq (8): in [0, 1], never falling."""
    views = [  # mean distances of 3 faces over 4 steps (nan: not in view)
        [3.5, np.nan, 0.2],
        [2.5, 4.0, np.nan],
        [3.0, 1.0, 1.4],  # face 0 farther than its best: d_f stays 2.5
        [1.5, 1.8, 1.6],  # face 2: |0.1| is not < |-0.1|: d_f stays 1.4
    ]
    best = np.full((1, 3), np.inf)
    paid = []
    for distance in views:
        best = updated_best(np.array([distance]), best, D_REF)
        paid.append(float(inspected_fraction(best, D_REF, BETA)[0]))
    np.testing.assert_array_equal(best[0], [1.5, 1.8, 1.4])
    assert paid == sorted(paid) and paid[0] > 0.0 and paid[-1] <= 1.0
    np.testing.assert_allclose(paid[-1], distance_score(best[0], D_REF, BETA).mean())
    # nothing new seen: the same fraction is paid again (the level, not the gain)
    again = updated_best(np.full((1, 3), np.nan), best, D_REF)
    assert float(inspected_fraction(again, D_REF, BETA)[0]) == paid[-1]
    every_face_at_d_ref = np.full((2, 60), D_REF)
    np.testing.assert_array_equal(inspected_fraction(every_face_at_d_ref, D_REF, BETA), [1.0, 1.0])


def _shaped_stream(stream: np.ndarray, discount: float, crashed: bool) -> np.ndarray:
    """The shaped pay of steps 1..T of a fraction stream f_0..f_T (f_0: the reset's view)."""
    paid = shaped_fraction(stream[1:], stream[:-1], discount)
    if crashed:
        paid[-1] -= shaping_forfeit(stream[-1:], discount)[0]
    return paid


@pytest.mark.parametrize("crashed", [True, False])
def test_shaping_keeps_the_streams_discounted_return_up_to_the_start_potential(crashed):
    # Ng et al.'s identity: sum_k g^(k-1) r'_k = sum_k g^(k-1) f_k + g^T Phi_T - Phi_0, with
    # Phi_T = 0 after a crash; after a timeout the shaped value V - Phi bootstraps the rest
    discount = 0.99
    stream = np.minimum(np.cumsum(np.random.default_rng(3).uniform(0.0, 0.04, 60)), 1.0)
    weights = discount ** np.arange(len(stream) - 1)
    streamed = weights @ stream[1:]
    end = 0.0 if crashed else discount ** (len(stream) - 1) * stream[-1] / (1 - discount)
    shaped = weights @ _shaped_stream(stream, discount, crashed) - end
    assert shaped == pytest.approx(streamed - stream[0] / (1 - discount), rel=1e-12)


def test_shaping_pays_a_face_when_it_is_seen_and_nothing_while_the_fraction_holds():
    paid = shaped_fraction(np.array([0.3, 0.3]), np.array([0.2, 0.3]), 0.99)
    np.testing.assert_allclose(paid, [10.0, 0.0])
    # a crash at f = 0.5 forfeits what the stream would still have paid, g f / (1 - g)
    assert shaping_forfeit(np.array([0.5]), 0.99)[0] == pytest.approx(49.5)
