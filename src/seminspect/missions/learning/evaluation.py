"""The evaluation protocol of 004 Sec IV-A: coverage, crashes and timeouts per obstacle count.

For each obstacle count K, exactly ``episodes`` rooms are run to the end of their episode
(batches of at most ``num_envs`` rooms stepped together without autoreset, so each room runs
one episode and then freezes). A crash is contact with anything; a timeout is an episode that
stayed collision-free to its end (Sec IV-A), so crash % + timeout % = 100 %; both come with
Wilson 95 % intervals.

Coverage is measured two ways. Lenient (policy v1's figure): the share of the target's N_f
faces seen within ``inspect_range``. Strict (004 Fig 5: "all feasible faces ... seen within the
required inspection distance"): the share of the room's feasible faces
(:func:`~seminspect.missions.learning.feasibility.feasible_faces`, decided once per room at its
reset) seen once by the strict rule of the environment; a face seen strictly counts as
feasible. The coverage curves are strict, with the mean distance score over the same faces.

The rooms are the protocol's (:func:`evaluation_config`): what a policy sees and is paid comes
from its own environment settings. Each batch is reset with a seed derived from ``seed``, K and
the batch index, so two controllers evaluated with the same ``seed`` and ``num_envs`` meet the
same rooms; the rooms' fingerprints are kept to show it.
"""

from __future__ import annotations

import hashlib
import os
import time
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError
from scipy import stats

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import read_versioned_json, write_versioned_json
from seminspect.core.rng import make_rng
from seminspect.core.validation import build, describe_validation_error
from seminspect.missions.learning.baselines import Controller
from seminspect.missions.learning.batches import BatchStore, BatchTally
from seminspect.missions.learning.env import InspectionVectorEnv
from seminspect.missions.learning.env_config import EnvConfig, TargetShape
from seminspect.missions.learning.feasibility import feasible_faces
from seminspect.missions.learning.rooms import Room, struck_surface

FORMAT = "seminspect.rl-evaluation"
#: 2: strict coverage, intervals, the checkpoint's SHA-256 (version 1 is refused).
VERSION = 2
#: What remakes the stored evaluations (named when an old file is refused).
REGENERATE = ".venv/bin/python bench/rl_reproduction.py"
#: The rooms of every evaluation: 004 Sec IV-A's 10 x 10 x 4 m, Sec III-E's 90 s episodes,
#: obstacles anywhere that leaves the robot room to pass.
PROTOCOL_ROOMS: dict[str, object] = {
    "room_size": (10.0, 10.0, 4.0),
    "room_size_range": None,
    "episode_seconds": 90.0,
    "obstacle_rule": "surface",
}
#: 004 Table I (the trained policy): obstacles -> (coverage %, crash %, timeout %).
PAPER_TABLE1: dict[int, tuple[float, float, float]] = {
    0: (92.1, 0.0, 100.0),
    4: (82.6, 0.3, 99.7),
    9: (74.6, 1.2, 98.8),
    14: (64.2, 1.5, 98.5),
    19: (58.1, 1.3, 98.7),
}
#: 004 Table II (9 obstacles): coverage %, crash %, timeout % without and with the SVS map.
PAPER_TABLE2: dict[str, tuple[float, float, float]] = {
    "m^o": (52.3, 1.0, 99.0),
    "m^o & m^h": (74.6, 1.2, 98.8),
}
#: 004 Table III (9 obstacles): the same without a GRU and with GRUs of 128 and 512 units.
PAPER_TABLE3: dict[str, tuple[float, float, float]] = {
    "no GRU": (59.8, 3.6, 96.4),
    "GRU 128": (63.6, 1.1, 99.1),
    "GRU 512": (74.6, 1.2, 98.8),
}
#: Coverage curves are kept at this interval (s), and in full for this many episodes per K.
CURVE_INTERVAL = 1.0
KEPT_CURVES = 4

Progress = Callable[[str, float], None]


class ObstacleResult(BaseModel):
    """Outcome of every episode at one obstacle count (percentages in 0-100).

    Intervals are 95 %: Wilson's for the crash and timeout rates, Student's t for the mean
    strict coverage.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    obstacles: int
    episodes: int
    coverage_pct: float
    strict_coverage_pct: float
    strict_coverage_ci: tuple[float, float]
    #: Mean over episodes of the mean distance score (0-1) of their feasible faces.
    distance_score: float
    crash_pct: float
    crash_ci: tuple[float, float]
    timeout_pct: float
    timeout_ci: tuple[float, float]
    #: Per episode: final lenient and strict coverage %, distance score, feasible faces (or
    #: seen strictly), crashed or not, steps flown, room fingerprint.
    coverage: list[float]
    strict_coverage: list[float]
    distance_scores: list[float]
    feasible_faces: list[int]
    crashed: list[bool]
    length: list[int]
    #: What each crash struck (one of ``rooms.SURFACES``; "" for no crash); empty in files
    #: written before it was recorded.
    struck: list[str] = Field(default_factory=list)
    rooms: list[str]
    #: Strict coverage % against ``curve_times``: mean, 5th and 95th percentile over the
    #: episodes, and the curves of the first ``KEPT_CURVES`` episodes.
    curve_times: list[float]
    curve_mean: list[float]
    curve_p5: list[float]
    curve_p95: list[float]
    curves: list[list[float]]

    def crashes_into(self) -> dict[str, int]:
        """Crashes per surface struck, most first (empty when not recorded)."""
        counts = Counter(name for name in self.struck if name)
        return dict(counts.most_common())


class EvaluationResult(BaseModel):
    """One controller evaluated at several obstacle counts."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    policy: str
    seed: int
    num_envs: int
    #: The environment's settings (:func:`evaluation_config`); each row replaces
    #: ``obstacles`` with its own count.
    config: EnvConfig
    #: SHA-256 of the checkpoint file flown; None for a baseline.
    checkpoint_sha256: str | None
    #: The env config the flown policy was trained in (its checkpoint's); None for a baseline.
    policy_env_config: EnvConfig | None = None
    #: Seconds spent flying the batches, summed (a resumed evaluation's stored ones too).
    wall_seconds: float
    results: list[ObstacleResult]

    def at(self, obstacles: int) -> ObstacleResult:
        """The result for one obstacle count."""
        for result in self.results:
            if result.obstacles == obstacles:
                return result
        raise InvalidInputError(f"no result for {obstacles} obstacles in this evaluation")

    def to_json(self, path: str | os.PathLike[str]) -> Path:
        """Write atomically as a versioned JSON document."""
        return write_versioned_json(path, FORMAT, VERSION, self.model_dump(mode="json"), indent=1)

    @classmethod
    def from_json(cls, path: str | os.PathLike[str]) -> EvaluationResult:
        document = read_versioned_json(path, FORMAT, [1, VERSION])
        if document["version"] == 1:
            raise FileFormatError(
                f"{path}: a version-1 evaluation (no strict coverage); regenerate it: {REGENERATE}"
            )
        payload = {k: v for k, v in document.items() if k not in {"format", "version"}}
        try:
            return cls.model_validate(payload)
        except ValidationError as exc:
            problem = describe_validation_error(exc, "evaluation")
            raise FileFormatError(f"{path}: {problem}") from None


@dataclass(frozen=True)
class EpisodeTrace:
    """What the pictures of one episode need: its room, track and face distances d_f.

    ``track`` rows are (x, y, z, yaw, coverage) from the reset on (see ``env.track``).
    """

    room: Room
    track: NDArray[np.float64]
    face_distances: NDArray[np.float64]
    crashed: bool


def evaluation_config(
    policy_env: EnvConfig, shapes: Sequence[TargetShape] = ("cylinder",)
) -> EnvConfig:
    """The protocol's rooms (:data:`PROTOCOL_ROOMS`, objects of ``shapes``) with everything a
    policy sees and is paid as in ``policy_env``, the environment it was trained in."""
    values = {**policy_env.model_dump(), **PROTOCOL_ROOMS, "target_shapes": tuple(shapes)}
    return build(EnvConfig, values, "evaluation environment")


def controller_evaluation_config(
    controller: Controller, shapes: Sequence[TargetShape] = ("cylinder",)
) -> EnvConfig:
    """:func:`evaluation_config` of the environment ``controller`` was trained in: its
    ``env_config`` (a checkpoint's); a baseline, trained in none, gets the defaults."""
    return evaluation_config(getattr(controller, "env_config", None) or EnvConfig(), shapes)


def room_fingerprint(room: Room) -> str:
    """A short digest of a room's geometry and start: equal rooms, equal fingerprints."""
    digest = hashlib.blake2b(digest_size=6)
    for array in (room.vertices, room.triangles, room.start):
        digest.update(np.ascontiguousarray(array).tobytes())
    return digest.hexdigest()


def batch_seed(seed: int, obstacles: int, batch: int) -> int:
    """The reset seed of one batch of rooms."""
    rng = make_rng(seed, "learning", "evaluation", f"obstacles-{obstacles}", f"batch-{batch}")
    return int(rng.integers(2**31))


def evaluate(
    controller: Controller,
    obstacle_counts: Sequence[int],
    episodes: int,
    seed: int,
    *,
    config: EnvConfig | None = None,
    num_envs: int = 64,
    progress: Progress | None = None,
    policy: str = "",
    threads: int = 1,
    traces: dict[int, EpisodeTrace] | None = None,
    checkpoint_sha256: str | None = None,
    store: BatchStore | None = None,
) -> EvaluationResult:
    """Run ``episodes`` rooms per obstacle count with ``controller`` (004 Sec IV-A).

    Args:
        controller: drives every batch (``reset`` after each environment reset).
        obstacle_counts: the K of each row (Table I: 0, 4, 9, 14, 19).
        episodes: rooms per obstacle count.
        seed: the rooms (and the environments' noise) follow from it.
        config: environment settings (default: :func:`evaluation_config` of the defaults);
            its ``obstacles`` is replaced by each K.
        num_envs: rooms stepped together.
        progress: called with a label and the share of all steps done.
        policy: the controller's name, kept in the result.
        threads: ray-casting threads of the environment.
        traces: if given, receives the first episode of each K for pictures.
        checkpoint_sha256: of the checkpoint ``controller`` flies, kept in the result.
        store: finished batches are kept there and taken from there instead of flown again
            (a stopped evaluation resumes; the first batch of a count is flown whenever
            ``traces`` wants its episode).
    """
    counts = _checked_protocol(obstacle_counts, episodes, num_envs)
    base = config or evaluation_config(EnvConfig())
    total = len(counts) * episodes * base.steps_per_episode
    results, seconds = [], 0.0
    for index, obstacles in enumerate(counts):
        cfg = build(EnvConfig, {**base.model_dump(), "obstacles": obstacles}, "environment")

        def advance(
            steps: int,
            before=index * episodes * cfg.steps_per_episode,
            label=f"{obstacles} obstacles",
        ) -> None:
            if progress is not None:
                progress(label, (before + steps) / total)

        tally = _run_count(
            controller,
            cfg,
            episodes,
            seed,
            num_envs=num_envs,
            threads=threads,
            traces=traces,
            advance=advance,
            store=store,
        )
        results.append(_summarise(obstacles, tally, cfg))
        seconds += tally.seconds
    return EvaluationResult(
        policy=policy,
        seed=seed,
        num_envs=num_envs,
        config=base,
        checkpoint_sha256=checkpoint_sha256,
        policy_env_config=getattr(controller, "env_config", None),
        wall_seconds=seconds,
        results=results,
    )


def _checked_protocol(obstacle_counts: Sequence[int], episodes: int, num_envs: int) -> list[int]:
    """The obstacle counts, once the protocol is known to make sense."""
    counts = [int(k) for k in obstacle_counts]
    if not counts:
        raise InvalidInputError("give at least one obstacle count")
    if any(k < 0 for k in counts):
        raise InvalidInputError(f"obstacle counts must be >= 0, got {counts}")
    if len(set(counts)) != len(counts):
        raise InvalidInputError(f"obstacle counts repeat: {counts}")
    if episodes < 1:
        raise InvalidInputError(f"episodes must be >= 1, got {episodes}")
    if num_envs < 1:
        raise InvalidInputError(f"num_envs must be >= 1, got {num_envs}")
    return counts


def _run_count(
    controller: Controller,
    config: EnvConfig,
    episodes: int,
    seed: int,
    *,
    num_envs: int,
    threads: int,
    traces: dict[int, EpisodeTrace] | None,
    advance: Callable[[int], None],
    store: BatchStore | None,
) -> BatchTally:
    """The ``episodes`` rooms of one obstacle count, in batches of at most ``num_envs`` rooms.

    ``advance`` hears the room-steps done in this count; ``traces`` gets its first episode.
    """
    tally, obstacles, steps = BatchTally(), config.obstacles, config.steps_per_episode
    for batch, first in enumerate(range(0, episodes, num_envs)):
        size = min(num_envs, episodes - first)
        record = traces is not None and batch == 0
        stored = None if record or store is None else store.load(config, seed, batch, size)
        if stored is not None:
            tally.extend(stored)
            advance((first + size) * steps)
            continue
        started = time.perf_counter()
        env = InspectionVectorEnv(size, config, autoreset=False, record=record, threads=threads)

        def advance_batch(step: int, before=first * steps, size=size) -> None:
            advance(before + step * size)

        flown = _run_batch(env, controller, batch_seed(seed, obstacles, batch), advance_batch)
        flown.seconds = time.perf_counter() - started
        if store is not None:
            store.save(config, seed, batch, flown)
        tally.extend(flown)
        if record and traces is not None:
            traces[obstacles] = EpisodeTrace(
                env.rooms[0], env.track(0), env.face_distances(0), flown.crashed[0]
            )
    return tally


def _run_batch(
    env: InspectionVectorEnv,
    controller: Controller,
    reset_seed: int,
    advance: Callable[[int], None],
) -> BatchTally:
    """One episode in every room of ``env``, and their outcomes.

    The rooms' feasible faces are drawn from ``reset_seed`` too.
    """
    cfg = env.config
    steps = cfg.steps_per_episode
    every = max(1, round(CURVE_INTERVAL * cfg.control_hz))
    obs, _ = env.reset(seed=reset_seed)
    controller.reset(env)
    fingerprints = [room_fingerprint(room) for room in env.rooms]
    feasible = np.array([feasible_faces(room, cfg, reset_seed) for room in env.rooms])
    crashed = np.zeros(env.num_envs, dtype=bool)
    timed_out = np.zeros(env.num_envs, dtype=bool)
    length = np.full(env.num_envs, steps)
    struck = [""] * env.num_envs
    seen = [env.strict_seen()]
    for step in range(1, steps + 1):
        if not (crashed | timed_out).all():  # finished rooms are frozen: nothing left to step
            obs, _, crash, timeout, _ = env.step(controller.act(env, obs))
            length[crash] = step
            if crash.any():
                where = env.positions()
                for e in np.flatnonzero(crash):
                    struck[e] = struck_surface(env.rooms[e], where[e])
            crashed |= crash
            timed_out |= timeout
        if step % every == 0:
            seen.append(env.strict_seen())
            advance(step)
    # Scored over the faces feasible or seen strictly: a face seen strictly was feasible.
    scored = feasible | seen[-1]
    counts = scored.sum(axis=1)
    curves = np.array(seen).sum(axis=2).T  # strictly seen faces only accumulate
    return BatchTally(
        coverage=(100.0 * env.coverage()).tolist(),
        strict=_share(100.0 * curves[:, -1], counts, 100.0).tolist(),
        scores=_share((env.distance_scores() * scored).sum(axis=1), counts, 1.0).tolist(),
        feasible=counts.tolist(),
        crashed=crashed.tolist(),
        timed_out=timed_out.tolist(),
        length=length.tolist(),
        struck=struck,
        rooms=fingerprints,
        curves=list(_share(100.0 * curves, counts[:, None], 100.0)),
    )


def _share(total: NDArray, counts: NDArray, empty: float) -> NDArray[np.float64]:
    """``total / counts``; a room with no feasible face missed nothing: ``empty`` (full marks)."""
    out = np.full(np.broadcast_shapes(total.shape, counts.shape), empty)
    return np.divide(total, counts, out=out, where=counts > 0)


def wilson_pct(flags: Sequence[bool]) -> tuple[float, float]:
    """Wilson 95 % interval (in %) of the rate of ``True`` among ``flags``."""
    interval = stats.binomtest(int(np.sum(flags)), len(flags)).proportion_ci(method="wilson")
    return 100.0 * float(interval.low), 100.0 * float(interval.high)


def interval_text(value: float, interval: tuple[float, float]) -> str:
    """``"56.2 [48.0-64.4]"``: a percentage and its interval, one decimal (as 004's tables)."""
    return f"{value:.1f} [{interval[0]:.1f}-{interval[1]:.1f}]"


def mean_interval_pct(values: Sequence[float]) -> tuple[float, float]:
    """Student-t 95 % interval of the mean of percentages, kept within 0-100.

    One value tells nothing of the spread: (0, 100); equal values give a point.
    """
    if len(values) < 2:
        return 0.0, 100.0
    mean, sem = float(np.mean(values)), float(stats.sem(values))
    if sem == 0.0:
        return mean, mean
    low, high = stats.t.interval(0.95, len(values) - 1, loc=mean, scale=sem)
    return max(0.0, float(low)), min(100.0, float(high))


def _summarise(obstacles: int, tally: BatchTally, config: EnvConfig) -> ObstacleResult:
    curves = np.array(tally.curves)
    interval = max(1, round(CURVE_INTERVAL * config.control_hz)) / config.control_hz
    return ObstacleResult(
        obstacles=obstacles,
        episodes=len(tally.coverage),
        coverage_pct=float(np.mean(tally.coverage)),
        strict_coverage_pct=float(np.mean(tally.strict)),
        strict_coverage_ci=mean_interval_pct(tally.strict),
        distance_score=float(np.mean(tally.scores)),
        crash_pct=100.0 * float(np.mean(tally.crashed)),
        crash_ci=wilson_pct(tally.crashed),
        timeout_pct=100.0 * float(np.mean(tally.timed_out)),
        timeout_ci=wilson_pct(tally.timed_out),
        coverage=tally.coverage,
        strict_coverage=tally.strict,
        distance_scores=tally.scores,
        feasible_faces=tally.feasible,
        crashed=tally.crashed,
        length=tally.length,
        struck=tally.struck,
        rooms=tally.rooms,
        curve_times=[round(i * interval, 6) for i in range(curves.shape[1])],
        curve_mean=curves.mean(axis=0).tolist(),
        curve_p5=np.percentile(curves, 5, axis=0).tolist(),
        curve_p95=np.percentile(curves, 95, axis=0).tolist(),
        curves=curves[:KEPT_CURVES].tolist(),
    )
