"""A watched episode of ``rl show``: the same flight as an unwatched one, and states that tell
the truth about it, its ending included."""

from __future__ import annotations

import time

import numpy as np
import pytest

from seminspect.missions.learning.baselines import OrbitController, RandomController
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.feasibility import feasible_faces
from seminspect.missions.learning.live import (
    CRASHED,
    INTERRUPTED,
    TIMEOUT,
    LiveScene,
    LiveState,
    LiveWatch,
    play_episode,
)
from seminspect.missions.learning.rooms import SURFACES

SHORT = EnvConfig(obstacles=4, episode_seconds=8.0)


class _EveryStep:
    """A feed that wants every state and keeps them (each is built of copies)."""

    def __init__(self, every: int = 1) -> None:
        self.scene: LiveScene | None = None
        self.states: list[LiveState] = []
        self.asked = 0
        self.every = every

    def start(self, scene: LiveScene) -> None:
        self.scene = scene

    def ready(self) -> bool:
        self.asked += 1
        return self.asked % self.every == 0

    def publish(self, state: LiveState) -> None:
        self.states.append(state)


def _same_flight(a, b) -> None:
    assert np.array_equal(a.trace.track, b.trace.track)
    assert np.array_equal(a.trace.face_distances, b.trace.face_distances)
    assert np.array_equal(a.strict, b.strict)
    assert (a.steps, a.episode_return, a.coverage, a.ending) == (
        b.steps, b.episode_return, b.coverage, b.ending
    )  # fmt: skip


@pytest.mark.parametrize("every", [1, 7])
def test_a_watched_episode_flies_as_an_unwatched_one(every: int) -> None:
    plain = play_episode(OrbitController(), SHORT, seed=2)
    feed = _EveryStep(every)
    seen = play_episode(OrbitController(), SHORT, seed=2, watch=LiveWatch(feed))
    _same_flight(plain, seen)
    assert plain.ending == TIMEOUT and plain.steps == SHORT.steps_per_episode


def test_states_follow_the_episode() -> None:
    feed = _EveryStep()
    flown = play_episode(OrbitController(), SHORT, seed=2, watch=LiveWatch(feed))
    scene, states = feed.scene, feed.states
    assert scene is not None and scene.room.obstacle_count == 4
    assert np.array_equal(scene.feasible, feasible_faces(flown.trace.room, SHORT, 2))
    # the reset, every step, then the final state again
    assert [s.step for s in states] == [*range(flown.steps + 1), flown.steps]
    assert all(len(s.track) == s.step + 1 for s in states)
    assert np.array_equal(states[-1].track, flown.trace.track)
    assert [s.coverage for s in states[:-1]] == pytest.approx(flown.trace.track[:, 4].tolist())
    assert states[-1].episode_return == pytest.approx(flown.episode_return)
    assert np.array_equal(states[-1].strict, flown.strict)
    assert np.diff([s.strict.sum() for s in states]).min() >= 0
    assert states[0].depth.shape == (SHORT.image_size[1], SHORT.image_size[0])
    assert [s.ended for s in states[:-1]] == [None] * (len(states) - 1)
    assert (states[-1].ended, states[-1].struck) == (TIMEOUT, "")


def test_a_crash_ends_the_episode_and_says_what_it_struck() -> None:
    config = EnvConfig(obstacles=0, episode_seconds=30.0)
    feed = _EveryStep()
    flown = play_episode(RandomController(0), config, seed=0, watch=LiveWatch(feed))
    assert flown.ending == CRASHED and flown.steps < config.steps_per_episode
    last = feed.states[-1]
    assert last.ended == CRASHED and last.struck in SURFACES and last.step == flown.steps


def test_ctrl_c_shows_the_episode_as_interrupted() -> None:
    feed = _EveryStep()

    def stop(step: int) -> None:
        if step == 5:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        play_episode(OrbitController(), SHORT, seed=2, watch=LiveWatch(feed), progress=stop)
    assert (feed.states[-1].ended, feed.states[-1].step) == (INTERRUPTED, 5)


def test_a_real_time_watch_holds_each_step_to_the_clock() -> None:
    config = EnvConfig(obstacles=0, episode_seconds=0.5)  # five steps at 10 Hz
    started = time.monotonic()
    paced = play_episode(
        OrbitController(), config, seed=2, watch=LiveWatch(_EveryStep(), real_time=True)
    )
    assert time.monotonic() - started >= 0.5
    _same_flight(paced, play_episode(OrbitController(), config, seed=2))
