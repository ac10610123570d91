"""The 004 Sec IV-A protocol: exact episode counts, shared rooms, outcome rates, JSON."""

import numpy as np
import pytest

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.missions.learning.baselines import OrbitController, RandomController
from seminspect.missions.learning.env import EnvConfig
from seminspect.missions.learning.evaluation import EvaluationResult, batch_seed, evaluate

SHORT = EnvConfig(episode_seconds=3.0)


@pytest.fixture(scope="module")
def runs():
    traces = {}
    shares = []
    orbit = evaluate(
        OrbitController(), [0, 14], 5, seed=1, config=SHORT, num_envs=2, policy="orbit",
        traces=traces, progress=lambda label, share: shares.append(share),
    )  # fmt: skip
    random = evaluate(RandomController(), [0, 14], 5, seed=1, config=SHORT, num_envs=2)
    return orbit, random, traces, shares


def test_every_obstacle_count_runs_exactly_the_episodes_asked(runs):
    orbit, _, _, shares = runs
    assert [r.obstacles for r in orbit.results] == [0, 14]
    for row in orbit.results:
        assert row.episodes == 5 == len(row.coverage) == len(row.crashed) == len(row.rooms)
        assert len(set(row.rooms)) == 5  # five different rooms (3 batches of 2, 2, 1)
        assert row.crash_pct + row.timeout_pct == pytest.approx(100.0)
        assert row.crash_pct == pytest.approx(100.0 * np.mean(row.crashed))
        assert row.coverage_pct == pytest.approx(np.mean(row.coverage))
        crashed_lengths = np.array(row.length)[np.array(row.crashed)]
        assert np.all(crashed_lengths <= SHORT.steps_per_episode)
        assert len(row.curve_mean) == len(row.curve_times) == 4  # 0, 1, 2, 3 s
        assert np.all(np.diff(row.curve_mean) >= 0)  # coverage never falls
        assert row.curve_mean[-1] == pytest.approx(row.coverage_pct)
    assert shares == sorted(shares) and shares[-1] == pytest.approx(1.0)


def test_two_controllers_meet_the_same_rooms(runs):
    orbit, random, _, _ = runs
    for a, b in zip(orbit.results, random.results, strict=True):
        assert a.rooms == b.rooms
    other = evaluate(RandomController(), [0], 2, seed=2, config=SHORT, num_envs=2)
    assert other.at(0).rooms != random.at(0).rooms[:2]
    assert batch_seed(1, 0, 0) != batch_seed(1, 4, 0) != batch_seed(1, 0, 1)


def test_the_first_episode_of_each_count_is_traced(runs):
    orbit, _, traces, _ = runs
    assert sorted(traces) == [0, 14]
    trace = traces[14]
    assert trace.room.obstacle_count == 14
    assert trace.track.shape == (SHORT.steps_per_episode + 1, 5) or trace.crashed
    assert trace.track[-1, 4] * 100 == pytest.approx(orbit.at(14).coverage[0])


def test_the_result_round_trips_through_json(runs, tmp_path):
    orbit = runs[0]
    path = orbit.to_json(tmp_path / "evaluation.json")
    assert EvaluationResult.from_json(path) == orbit
    assert '"coverage_pct"' in path.read_text()
    path.write_text(path.read_text().replace('"episodes"', '"runs"', 1))
    with pytest.raises(FileFormatError, match="evaluation"):
        EvaluationResult.from_json(path)


@pytest.mark.parametrize(
    ("counts", "episodes", "message"),
    [
        ([], 1, "at least one"),
        ([0, 0], 1, "repeat"),
        ([-1], 1, ">= 0"),
        ([0], 0, "episodes"),
        ([61], 1, "obstacles"),
    ],
)
def test_bad_protocols_are_refused(counts, episodes, message):
    with pytest.raises(InvalidInputError, match=message):
        evaluate(RandomController(), counts, episodes, seed=0, config=SHORT)
