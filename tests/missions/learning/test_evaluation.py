"""The 004 Sec IV-A protocol: exact episode counts, shared rooms, strict coverage, intervals,
JSON."""

import json

import numpy as np
import pytest

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.missions.learning import evaluation as evaluation_module
from seminspect.missions.learning.baselines import OrbitController, RandomController
from seminspect.missions.learning.env import EnvConfig
from seminspect.missions.learning.evaluation import (
    PROTOCOL_ROOMS,
    EvaluationResult,
    batch_seed,
    evaluate,
    evaluation_config,
    interval_text,
    mean_interval_pct,
    wilson_pct,
)
from seminspect.missions.learning.rooms import SURFACES

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
        assert row.crash_ci[0] <= row.crash_pct <= row.crash_ci[1]
        assert row.timeout_ci == pytest.approx((100 - row.crash_ci[1], 100 - row.crash_ci[0]))
        assert row.coverage_pct == pytest.approx(np.mean(row.coverage))
        assert row.strict_coverage_pct == pytest.approx(np.mean(row.strict_coverage))
        low, high = row.strict_coverage_ci
        assert 0.0 <= low <= row.strict_coverage_pct <= high <= 100.0
        assert 0.0 <= row.distance_score <= 1.0 and len(row.distance_scores) == 5
        crashed_lengths = np.array(row.length)[np.array(row.crashed)]
        assert np.all(crashed_lengths <= SHORT.steps_per_episode)
        assert len(row.curve_mean) == len(row.curve_times) == 4  # 0, 1, 2, 3 s
        assert np.all(np.diff(row.curve_mean) >= 0)  # coverage never falls
        assert row.curve_mean[-1] == pytest.approx(row.strict_coverage_pct)  # strict curves
    assert shares == sorted(shares) and shares[-1] == pytest.approx(1.0)


def test_strict_coverage_is_a_share_of_the_feasible_faces(runs):
    orbit, random, _, _ = runs
    side = 12 * 4  # a cylinder's 12 sectors x 4 bands; none of the 12 top faces
    for row in (orbit.at(0), random.at(0)):
        # an empty room: the whole side is feasible, the top is not (a level camera) and the
        # strict rule cannot see it either
        assert row.feasible_faces == [side] * row.episodes
    for row in (*orbit.results, *random.results):
        seen = np.array(row.strict_coverage) * np.array(row.feasible_faces) / 100.0
        np.testing.assert_allclose(seen, np.round(seen), atol=1e-9)  # whole faces
        assert all(0 < n <= 60 for n in row.feasible_faces)
    assert orbit.at(0).strict_coverage_pct > random.at(0).strict_coverage_pct


def test_a_face_seen_strictly_counts_as_feasible(monkeypatch):
    """Were no face found feasible, the strictly seen faces would still be scored."""
    truth = evaluate(OrbitController(), [0], 2, seed=1, config=SHORT, num_envs=2).at(0)
    shares = zip(truth.strict_coverage, truth.feasible_faces, strict=True)
    seen = [round(share * count / 100) for share, count in shares]
    assert max(seen) > 0  # the orbit sees some faces strictly within 3 s
    monkeypatch.setattr(
        evaluation_module, "feasible_faces", lambda room, config, seed: np.zeros(60, dtype=bool)
    )
    row = evaluate(OrbitController(), [0], 2, seed=1, config=SHORT, num_envs=2).at(0)
    assert row.feasible_faces == seen
    assert row.strict_coverage == [100.0, 100.0]  # seen / seen, or nothing to see


def test_intervals_come_from_wilson_and_student():
    assert wilson_pct([False] * 5) == pytest.approx((0.0, 43.448), abs=1e-3)
    assert wilson_pct([True, False]) == pytest.approx((9.453, 90.547), abs=1e-3)
    assert mean_interval_pct([40.0, 50.0, 60.0, 45.0, 55.0]) == pytest.approx(
        (40.184, 59.816), abs=1e-3
    )
    assert mean_interval_pct([70.0, 70.0]) == (70.0, 70.0)
    assert mean_interval_pct([30.0]) == (0.0, 100.0)  # one episode says nothing of the spread
    assert mean_interval_pct([0.0, 100.0])[0] == 0.0  # clipped to the percentage range
    assert interval_text(56.24, (48.0, 64.44)) == "56.2 [48.0-64.4]"


def test_the_protocol_fixes_the_rooms_and_keeps_what_the_policy_sees():
    legacy = EnvConfig.legacy(episode_seconds=45.0, room_size=(8.0, 8.0, 3.0), obstacles=3)
    config = evaluation_config(legacy, ("box", "sphere"))
    for key, value in PROTOCOL_ROOMS.items():
        assert getattr(config, key) == value
    assert config.target_shapes == ("box", "sphere")
    assert (config.ego_map, config.yaw_encoding, config.face_reward) == (
        "binary", "half-angle", "repaid",
    )  # fmt: skip
    assert evaluation_config(EnvConfig()).target_shapes == ("cylinder",)
    with pytest.raises(InvalidInputError, match="evaluation environment"):
        evaluation_config(EnvConfig(), ("torus",))  # type: ignore[arg-type]


def test_policies_trained_in_other_environments_meet_the_same_rooms():
    """The rooms follow the protocol and the seed, not what each policy sees or is paid."""
    short = {"episode_seconds": 1.0}
    new = evaluation_config(EnvConfig()).model_copy(update=short)
    old = evaluation_config(EnvConfig.legacy()).model_copy(update=short)
    assert new != old
    a = evaluate(RandomController(), [4], 2, seed=3, config=new, num_envs=2)
    b = evaluate(RandomController(), [4], 2, seed=3, config=old, num_envs=2)
    assert a.at(4).rooms == b.at(4).rooms
    assert a.at(4).feasible_faces == b.at(4).feasible_faces


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
    assert orbit.checkpoint_sha256 is None  # a baseline
    path = orbit.to_json(tmp_path / "evaluation.json")
    assert EvaluationResult.from_json(path) == orbit
    assert '"strict_coverage_pct"' in path.read_text()
    path.write_text(path.read_text().replace('"episodes"', '"runs"', 1))
    with pytest.raises(FileFormatError, match="evaluation"):
        EvaluationResult.from_json(path)


def test_every_crash_names_what_it_struck_and_older_files_load_without(runs, tmp_path):
    rows = [row for result in runs[:2] for row in result.results]
    crashes = sum(sum(row.crashed) for row in rows)
    assert crashes > 0  # the random controller crashes in the cluttered rooms
    for row in rows:
        assert [bool(name) for name in row.struck] == row.crashed
        assert set(row.struck) <= {"", *SURFACES}
        assert sum(row.crashes_into().values()) == sum(row.crashed)
    path = runs[1].to_json(tmp_path / "evaluation.json")
    document = json.loads(path.read_text())
    for row in document["results"]:
        del row["struck"]  # as written before crashes were named
    path.write_text(json.dumps(document))
    assert all(row.crashes_into() == {} for row in EvaluationResult.from_json(path).results)


def test_the_checkpoint_digest_is_kept_and_feasibility_is_decided_once_per_room(
    monkeypatch, tmp_path
):
    calls = []
    real = evaluation_module.feasible_faces
    monkeypatch.setattr(
        evaluation_module, "feasible_faces", lambda *args: calls.append(1) or real(*args)
    )
    digest = "ab" * 32
    result = evaluate(
        RandomController(), [0, 4], 3, seed=0, config=SHORT, num_envs=2, checkpoint_sha256=digest
    )
    assert len(calls) == 6  # 2 counts x 3 rooms, however many steps
    path = result.to_json(tmp_path / "evaluation.json")
    assert EvaluationResult.from_json(path).checkpoint_sha256 == digest


def test_a_version_1_file_is_refused_with_how_to_regenerate_it(runs, tmp_path):
    path = runs[0].to_json(tmp_path / "evaluation.json")
    document = json.loads(path.read_text())
    path.write_text(json.dumps(document | {"version": 1}))
    with pytest.raises(FileFormatError, match="version-1") as error:
        EvaluationResult.from_json(path)
    assert "bench/rl_reproduction.py" in str(error.value)
    assert len(str(error.value).splitlines()) == 1


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


def test_a_policy_with_an_env_config_has_it_recorded_beside_the_evaluated_one(tmp_path):
    class Trained(RandomController):
        env_config = EnvConfig.legacy(episode_seconds=45.0)

    result = evaluate(Trained(), [0], 1, seed=0, config=SHORT, num_envs=1)
    assert result.policy_env_config == Trained.env_config
    assert result.config == SHORT  # the rooms are the protocol's, not the training's
    restored = EvaluationResult.from_json(result.to_json(tmp_path / "evaluation.json"))
    assert restored.policy_env_config == Trained.env_config
    assert evaluate(RandomController(), [0], 1, 0, config=SHORT).policy_env_config is None


def test_strict_coverage_tells_a_good_inspection_from_a_distant_one_the_lenient_rule_cannot():
    """An orbit at d_ref and one 1.2 m farther both see the whole side within 3 m (lenient),
    but only the first sees it at the distance the inspection asks for (strict)."""
    config = EnvConfig(episode_seconds=30.0)
    good = evaluate(OrbitController(), [0], 4, seed=1, config=config, num_envs=4)
    far = evaluate(OrbitController(distance=2.7), [0], 4, seed=1, config=config, num_envs=4)
    assert good.at(0).rooms == far.at(0).rooms  # the same rooms
    assert good.at(0).coverage_pct > 60.0 and far.at(0).coverage_pct > 60.0
    assert good.at(0).strict_coverage_pct > 70.0
    assert far.at(0).strict_coverage_pct < 0.5 * good.at(0).strict_coverage_pct
