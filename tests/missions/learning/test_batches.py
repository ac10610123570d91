"""Stored evaluation batches: a stopped evaluation resumes to the same result, a batch flown
by anything else is never reused, a damaged one is refused."""

import pytest

from seminspect.core.errors import FileFormatError
from seminspect.missions.learning import batches as batches_module
from seminspect.missions.learning.baselines import OrbitController, RandomController
from seminspect.missions.learning.batches import BatchStore
from seminspect.missions.learning.env import EnvConfig
from seminspect.missions.learning.evaluation import evaluate

SHORT = EnvConfig(episode_seconds=2.0)
#: 5 episodes in batches of 2: three batches per obstacle count.
PROTOCOL = {"obstacle_counts": [0, 9], "episodes": 5, "seed": 1, "config": SHORT, "num_envs": 2}


def _outcomes(result):
    """Everything measured, without the seconds spent."""
    return result.model_dump(exclude={"wall_seconds"})


class StopAfter:
    """An orbit that stops the evaluation (as Ctrl-C would) after ``resets`` batches began."""

    def __init__(self, resets: int) -> None:
        self.orbit, self.left = OrbitController(), resets

    def reset(self, env):
        if self.left == 0:
            raise KeyboardInterrupt
        self.left -= 1
        self.orbit.reset(env)

    def act(self, env, obs):
        return self.orbit.act(env, obs)


def test_a_stopped_evaluation_resumes_from_its_finished_batches_to_the_same_result(tmp_path):
    whole = evaluate(OrbitController(), **PROTOCOL)
    store = BatchStore(tmp_path, {"evaluation": "orbit"})
    with pytest.raises(KeyboardInterrupt):
        evaluate(StopAfter(4), **PROTOCOL, store=store)  # 0 obstacles done, 9 one batch in
    assert len(list(tmp_path.glob("k0-*.json"))) == 3 and len(list(tmp_path.glob("k9-*"))) == 1
    flown: list[int] = []

    class Counting(OrbitController):
        def reset(self, env):
            flown.append(env.num_envs)
            super().reset(env)

    resumed = evaluate(Counting(), **PROTOCOL, store=store)
    assert flown == [2, 1]  # only the two batches the stop left
    assert _outcomes(resumed) == _outcomes(whole)
    assert len(list(tmp_path.glob("*.json"))) == 6


def test_batches_of_another_identity_seed_or_config_are_not_reused(tmp_path):
    evaluate(OrbitController(), **PROTOCOL, store=BatchStore(tmp_path, {"evaluation": "orbit"}))
    stored = {p.name for p in tmp_path.iterdir()}
    other = BatchStore(tmp_path, {"evaluation": "random"})
    random = evaluate(RandomController(), **PROTOCOL, store=other)
    assert _outcomes(random) == _outcomes(evaluate(RandomController(), **PROTOCOL))
    changed = PROTOCOL | {"seed": 2, "config": EnvConfig(episode_seconds=2.0, beta=2.0)}
    evaluate(RandomController(), **changed, store=other)
    names = {p.name for p in tmp_path.iterdir()}
    assert stored < names and len(names) == 3 * 6  # each run's own six batches


def test_a_damaged_batch_is_refused_with_its_name(tmp_path):
    store = BatchStore(tmp_path, {"evaluation": "orbit"})
    evaluate(OrbitController(), **PROTOCOL, store=store)
    damaged = sorted(tmp_path.glob("k9-b1-*.json"))[0]
    damaged.write_text(damaged.read_text()[:-40])
    with pytest.raises(FileFormatError, match=damaged.name):
        evaluate(OrbitController(), **PROTOCOL, store=store)


def test_a_batch_of_another_layout_version_is_flown_again(tmp_path, monkeypatch):
    store = BatchStore(tmp_path, {"evaluation": "orbit"})
    now = store.path(SHORT, 1, 0, 2)
    monkeypatch.setattr(batches_module, "BATCH_VERSION", batches_module.BATCH_VERSION - 1)
    assert store.path(SHORT, 1, 0, 2) != now  # an older file is never read as this layout
