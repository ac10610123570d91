"""One policy episode in one room, as ``seminspect rl show`` flies it, optionally seen live.

:func:`play_episode` resets a one-room
:class:`~seminspect.missions.learning.env.InspectionVectorEnv` (recording its track), lets a
controller fly it until it crashes or times out, and returns the :class:`EpisodeRun`. A
:class:`LiveWatch` given to it hands its :class:`LiveFeed` the room once (:class:`LiveScene`)
and then, whenever the feed is ready for more (a client is connected and the last state is old
enough), a :class:`LiveState`: the robot's pose and path, the step's reward and the return, the
faces seen so far (lenient: d_f within ``inspect_range``; strict: the strict rule met once,
counted against the room's feasible faces as evaluation does) and what the policy sees (its
masked depth image); the last state says how the episode ended. The watch reads the
environment through its public accessors only, which copy, and touches none of the episode's
random streams, so an episode flies the same watched or not.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from seminspect.missions.learning.baselines import Controller
from seminspect.missions.learning.env import InspectionVectorEnv
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.evaluation import EpisodeTrace
from seminspect.missions.learning.feasibility import feasible_faces
from seminspect.missions.learning.rooms import Room, struck_surface

#: How an episode can end: contact with anything, or its full length flown without.
CRASHED, TIMEOUT, INTERRUPTED = "crashed", "timeout", "interrupted"


@dataclass(frozen=True)
class LiveScene:
    """What does not change during an episode: the room, the settings it is flown with, and
    which of its object's faces can be inspected strictly at all."""

    room: Room
    config: EnvConfig
    feasible: NDArray[np.bool_]


@dataclass(frozen=True)
class LiveState:
    """The episode as it stands after ``step`` steps (0: just reset).

    Attributes:
        track: ``(T, 5)`` rows so far (x, y, z, yaw, lenient coverage), from the reset on.
        reward: the last step's reward (0 at the reset); episode_return: their sum.
        face_distances: best viewing distance d_f of each object face (inf: never seen).
        strict: whether each face met the strict rule once.
        depth: what the policy sees: the masked depth D_t∘S_t, ``(H, W)`` in [0, 1].
        ended: ``crashed``, ``timeout`` or ``interrupted`` in the last state; None before.
        struck: what a crash struck (one of ``rooms.SURFACES``), else "".
    """

    step: int
    steps_total: int
    control_hz: float
    track: NDArray[np.float64]
    reward: float
    episode_return: float
    coverage: float
    face_distances: NDArray[np.float64]
    strict: NDArray[np.bool_]
    feasible: NDArray[np.bool_]
    inspect_range: float
    depth: NDArray[np.float32]
    ended: str | None = None
    struck: str = ""


class LiveFeed(Protocol):
    """Where a watched episode's states go (the live view's server)."""

    def start(self, scene: LiveScene) -> None:
        """The episode's room, before its first state."""
        ...

    def ready(self) -> bool:
        """Whether a new state is wanted now (cheap: asked at every step)."""
        ...

    def publish(self, state: LiveState) -> None:
        """Take a state."""
        ...


@dataclass(frozen=True)
class EpisodeRun:
    """A flown episode: what its pictures need, and its outcome."""

    trace: EpisodeTrace
    steps: int
    episode_return: float
    coverage: float
    strict: NDArray[np.bool_]
    ending: str


class LiveWatch:
    """Shows an episode to a :class:`LiveFeed` (see the module docstring).

    ``real_time``: hold each step until its simulated time has passed on the wall clock, so a
    person sees the episode at the env's control rate (a baseline flies 90 s in a few
    otherwise); the flight itself is the same either way.
    """

    def __init__(self, feed: LiveFeed, *, real_time: bool = False) -> None:
        self.feed = feed
        self.real_time = real_time
        self._feasible: NDArray[np.bool_] = np.zeros(0, dtype=bool)
        self._return = self._reward = 0.0
        self._started = time.monotonic()

    def start(self, env: InspectionVectorEnv, seed: int, obs: dict[str, NDArray]) -> None:
        """The episode of room 0 has just been reset: its scene, then its first state."""
        room = env.rooms[0]
        self._feasible = feasible_faces(room, env.config, seed)  # as evaluation decides them
        self._return = self._reward = 0.0
        self._started = time.monotonic()
        self.feed.start(LiveScene(room, env.config, self._feasible))
        self.step(env, obs, 0, 0.0)

    def step(
        self, env: InspectionVectorEnv, obs: dict[str, NDArray], step: int, reward: float
    ) -> None:
        """After each step: the state, when the feed wants one."""
        self._reward = reward
        self._return += reward
        if self.real_time:
            ahead = step / env.config.control_hz - (time.monotonic() - self._started)
            time.sleep(max(0.0, ahead))
        if self.feed.ready():
            self.feed.publish(self.state(env, obs, step))

    def finish(
        self, env: InspectionVectorEnv, obs: dict[str, NDArray], step: int, ending: str
    ) -> None:
        """The last state, always sent: how the episode ended."""
        self.feed.publish(self.state(env, obs, step, ending))

    def state(
        self,
        env: InspectionVectorEnv,
        obs: dict[str, NDArray],
        step: int,
        ended: str | None = None,
    ) -> LiveState:
        """Room 0's episode now, read through the environment's copying accessors."""
        track = env.track(0)
        struck = struck_surface(env.rooms[0], track[-1, :3]) if ended == CRASHED else ""
        return LiveState(
            step=step,
            steps_total=env.config.steps_per_episode,
            control_hz=env.config.control_hz,
            track=track,
            reward=self._reward,
            episode_return=self._return,
            coverage=float(env.coverage()[0]),
            face_distances=env.face_distances(0),
            strict=env.strict_seen()[0],
            feasible=self._feasible,
            inspect_range=env.config.inspect_range,
            depth=np.array(obs["depth"][0, 0]),
            ended=ended,
            struck=struck,
        )


def play_episode(
    controller: Controller,
    config: EnvConfig,
    seed: int,
    *,
    watch: LiveWatch | None = None,
    progress: Callable[[int], None] | None = None,
) -> EpisodeRun:
    """Fly one episode of ``config``'s rooms drawn from ``seed``, to a crash or its full
    length; ``progress`` gets the step count after each step. Ctrl-C ends it, shown to the
    watch as ``interrupted``, and is raised on."""
    env = InspectionVectorEnv(1, config, seed=seed, autoreset=False, record=True)
    obs, _ = env.reset(seed=seed)
    controller.reset(env)
    if watch is not None:
        watch.start(env, seed, obs)
    crashed, steps, total = False, 0, 0.0
    try:
        for steps in range(1, config.steps_per_episode + 1):
            obs, reward, crash, _, _ = env.step(controller.act(env, obs))
            total += float(reward[0])
            crashed = bool(crash[0])
            if watch is not None:
                watch.step(env, obs, steps, float(reward[0]))
            if progress is not None:
                progress(steps)
            if crashed:
                break
    except KeyboardInterrupt:
        if watch is not None:
            watch.finish(env, obs, steps, INTERRUPTED)
        raise
    ending = CRASHED if crashed else TIMEOUT
    if watch is not None:
        watch.finish(env, obs, steps, ending)
    trace = EpisodeTrace(env.rooms[0], env.track(0), env.face_distances(0), crashed)
    coverage = float(env.coverage()[0])
    return EpisodeRun(trace, steps, total, coverage, env.strict_seen()[0], ending)
