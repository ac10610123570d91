"""Recurrent PPO for the inspection policy of 004, in one file read top to bottom.

004 Sec III-D trains its policy with Sample Factory's APPO. This trainer is synchronous PPO with
the same ingredients that matter for the task: a GRU carried through rollouts and reset at
episode boundaries, generalised advantage estimation, the clipped surrogate, a value loss, an
entropy bonus, gradient clipping and advantage normalisation. Why not a library:

* Sample Factory is built for throughput with many processes: its asynchronous mode runs
  rollout workers, inference workers and the learner as separate processes, each with its own
  copy of the model. It does have a synchronous mode and a serial (one-process) mode meant for
  debugging, but it brings its own configuration, environment registry and model builder, and
  on a 2-core machine its parallelism buys nothing over one process stepping a batched env.
* sb3-contrib's RecurrentPPO takes Dict observations (``MultiInputLstmPolicy``), but its memory
  is an LSTM, not the paper's GRU (004 Table III compares GRU sizes), its default feature
  extractor has no 3D convolution for the 21^3 maps, and it expects SB3's own ``VecEnv`` rather
  than a Gymnasium ``VectorEnv``. Each of these needs a custom class inside SB3's machinery.

So the algorithm lives here in a few hundred lines, its hyper-parameters in :class:`TrainConfig`.

Other choices: a truncated episode (the paper's "timeout", the usual end) is bootstrapped with
the value of its last observation rather than treated as terminal; rewards may be scaled by a
running standard deviation of the discounted return; obstacles enter by a curriculum (004 trains
with nine obstacles and sets up a curriculum without giving its schedule: ours steps through
obstacle counts at fractions of the training, 0, 4 then 9 by default).
"""

from __future__ import annotations

import csv
import dataclasses
import io
import math
import pickle
import time
import zipfile
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, Protocol

import numpy as np
import torch
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator
from torch import Tensor

from seminspect.core.errors import FileFormatError
from seminspect.core.interrupts import deferred_signals
from seminspect.core.io import atomic_write_text, atomic_write_with
from seminspect.core.rng import make_rng
from seminspect.core.validation import describe_validation_error
from seminspect.missions.learning.policy import (
    ACTION_SIZE,
    DEPTH_SHAPE,
    MAPS_SHAPE,
    STATE_SIZE,
    InspectionPolicy,
    PolicyConfig,
    as_tensors,
    gaussian_entropy,
    gaussian_log_prob,
)

CHECKPOINT_FORMAT = "seminspect-rl-policy"
CHECKPOINT_VERSION = 1
CHECKPOINT_NAME = "checkpoint.pt"


class VectorEnv(Protocol):
    """What the trainer needs of an environment (the contract of ``learning.env``)."""

    num_envs: int

    def reset(self, *, seed: int | None = None) -> tuple[dict[str, np.ndarray], dict]: ...

    def step(
        self, actions: np.ndarray
    ) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray, np.ndarray, dict]: ...

    def set_obstacles(self, counts: int) -> None: ...

    def close(self) -> None: ...


class TrainConfig(BaseModel):
    """Every hyper-parameter of a training run."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    total_steps: int = Field(2_000_000, gt=0, description="environment steps, all envs together")
    num_envs: int = Field(64, gt=0)
    rollout_steps: int = Field(32, gt=0, description="steps per env between updates")
    epochs: int = Field(4, gt=0)
    minibatches: int = Field(4, gt=0, description="env-sequence minibatches per epoch")
    lr: float = Field(3e-4, gt=0)
    anneal_lr: bool = True
    gamma: float = Field(0.99, gt=0, le=1)
    gae_lambda: float = Field(0.95, ge=0, le=1)
    clip: float = Field(0.2, gt=0)
    ent_coef: float = Field(0.0, ge=0)
    vf_coef: float = Field(0.5, ge=0)
    max_grad_norm: float = Field(0.5, gt=0)
    normalize_rewards: bool = True
    #: (fraction of training, obstacle count) steps; empty: leave the env's own count.
    curriculum: tuple[tuple[float, int], ...] = ((0.0, 0), (0.25, 4), (0.5, 9))
    checkpoint_every: int = Field(100_000, gt=0, description="environment steps")
    seed: int = Field(0, ge=0)
    threads: int = Field(1, gt=0, description="torch threads (the envs share the cores)")

    @model_validator(mode="after")
    def _check(self) -> TrainConfig:
        if self.num_envs % self.minibatches:
            raise ValueError(
                f"num_envs ({self.num_envs}) must be a multiple of minibatches "
                f"({self.minibatches}): minibatches are whole env sequences"
            )
        fractions = [fraction for fraction, _ in self.curriculum]
        if any(not 0 <= f < 1 for f in fractions) or fractions != sorted(set(fractions)):
            raise ValueError(f"curriculum fractions must rise within [0, 1), got {fractions}")
        if any(count < 0 for _, count in self.curriculum):
            raise ValueError("curriculum obstacle counts must be >= 0")
        return self

    @property
    def steps_per_update(self) -> int:
        return self.num_envs * self.rollout_steps

    @property
    def updates(self) -> int:
        return math.ceil(self.total_steps / self.steps_per_update)

    def obstacles_at(self, fraction: float) -> int | None:
        """The curriculum's obstacle count at this fraction of training (None: no curriculum
        step reached yet)."""
        reached = [count for start, count in self.curriculum if start <= fraction]
        return reached[-1] if reached else None


@dataclasses.dataclass(frozen=True)
class ProgressRow:
    """One line of ``progress.csv``, written after every update."""

    update: int
    steps: int
    wall_s: float
    steps_per_s: float
    obstacles: int | None
    episodes: int  # episodes that ended during this update's rollout
    mean_return: float  # NaN when none ended
    coverage_pct: float
    crash_pct: float
    timeout_pct: float
    policy_loss: float
    value_loss: float
    entropy: float
    approx_kl: float
    clip_fraction: float
    lr: float


@dataclasses.dataclass(frozen=True)
class TrainResult:
    """What :func:`train` leaves behind."""

    steps: int
    updates: int
    wall_s: float
    checkpoint: Path
    last: ProgressRow | None
    tensorboard: bool  # whether event files were written


@dataclasses.dataclass(frozen=True)
class Checkpoint:
    """A saved policy with the configurations that produced it."""

    policy: InspectionPolicy
    policy_config: PolicyConfig
    train_config: TrainConfig | None
    steps: int


# --- the rollout --------------------------------------------------------------------------


@dataclasses.dataclass
class Rollout:
    """``rollout_steps`` x ``num_envs`` transitions, tensors with leading dims (T, N)."""

    obs: dict[str, Tensor]
    starts: Tensor  # 1.0 where the observation begins an episode
    raw_actions: Tensor  # (T, N, 4) unclipped Gaussian samples
    log_probs: Tensor
    values: Tensor
    rewards: Tensor  # scaled, with timeouts bootstrapped
    hidden0: Tensor  # (N, H) recurrent state before the first step
    next_value: Tensor = dataclasses.field(init=False)
    next_start: Tensor = dataclasses.field(init=False)

    @classmethod
    def empty(
        cls, steps: int, envs: int, hidden: int, device: torch.device | None = None
    ) -> Rollout:
        shapes = {"state": (STATE_SIZE,), "depth": DEPTH_SHAPE, "maps": MAPS_SHAPE}

        def zeros(*shape: int) -> Tensor:
            return torch.zeros(*shape, device=device)

        return cls(
            obs={key: zeros(steps, envs, *shape) for key, shape in shapes.items()},
            starts=zeros(steps, envs),
            raw_actions=zeros(steps, envs, ACTION_SIZE),
            log_probs=zeros(steps, envs),
            values=zeros(steps, envs),
            rewards=zeros(steps, envs),
            hidden0=zeros(envs, hidden),
        )


def advantages_gae(rollout: Rollout, gamma: float, lam: float) -> tuple[Tensor, Tensor]:
    """Generalised advantage estimates and returns (T, N). ``starts[t + 1]`` ends the episode
    of step t: no value flows back across it."""
    steps = rollout.rewards.shape[0]
    advantages = torch.zeros_like(rollout.rewards)
    running = torch.zeros_like(rollout.next_value)
    for t in reversed(range(steps)):
        if t == steps - 1:
            following, next_value = rollout.next_start, rollout.next_value
        else:
            following, next_value = rollout.starts[t + 1], rollout.values[t + 1]
        alive = 1.0 - following
        delta = rollout.rewards[t] + gamma * next_value * alive - rollout.values[t]
        running = delta + gamma * lam * alive * running
        advantages[t] = running
    return advantages, advantages + rollout.values


class ReturnScaler:
    """Divide rewards by a running standard deviation of the discounted return."""

    def __init__(self, envs: int, gamma: float):
        self.gamma = gamma
        self.returns = np.zeros(envs)
        self.count, self.mean, self.var = 1e-4, 0.0, 1.0

    def __call__(self, rewards: np.ndarray, done: np.ndarray) -> np.ndarray:
        self.returns = self.returns * self.gamma + rewards
        self._update(self.returns)
        self.returns[done] = 0.0
        return rewards / math.sqrt(self.var + 1e-8)

    def _update(self, batch: np.ndarray) -> None:
        # Chan et al.'s parallel mean/variance update
        n, mean, var = batch.size, float(batch.mean()), float(batch.var())
        total = self.count + n
        delta = mean - self.mean
        self.mean += delta * n / total
        self.var = (self.var * self.count + var * n + delta**2 * self.count * n / total) / total
        self.count = total


@dataclasses.dataclass
class EpisodeStats:
    """Statistics of the episodes that ended during one rollout (``info["episode"]``)."""

    returns: list[float] = dataclasses.field(default_factory=list)
    coverage: list[float] = dataclasses.field(default_factory=list)
    crashes: list[bool] = dataclasses.field(default_factory=list)
    timeouts: list[bool] = dataclasses.field(default_factory=list)

    def record(self, info: Mapping[str, Any]) -> None:
        if "episode" not in info:
            return
        rows = np.asarray(info["_episode"], dtype=bool)
        episode = info["episode"]
        self.returns.extend(np.asarray(episode["return"], dtype=float)[rows].tolist())
        self.coverage.extend(np.asarray(episode["coverage"], dtype=float)[rows].tolist())
        self.crashes.extend(np.asarray(episode["crash"], dtype=bool)[rows].tolist())
        self.timeouts.extend(np.asarray(episode["timeout"], dtype=bool)[rows].tolist())

    def mean(self, values: list[float] | list[bool], scale: float = 1.0) -> float:
        return scale * float(np.mean(values)) if values else math.nan


def _final_observations(info: Mapping[str, Any], rows: np.ndarray) -> dict[str, np.ndarray]:
    """The last observations of the episodes in ``rows`` from ``info["final_obs"]``: a dict
    of (num_envs, ...) arrays, or of per-env object arrays (Gymnasium's own vector envs)."""
    final = info["final_obs"]
    picked = {}
    for key in ("state", "depth", "maps"):
        column = np.asarray(final[key])
        picked[key] = np.stack(list(column[rows])) if column.dtype == object else column[rows]
    return picked


# --- the run --------------------------------------------------------------------------------


def _torch_seed(seed: int, stream: str) -> int:
    return int(make_rng(seed, "learning", "ppo", stream).integers(2**62))


class _Run:
    """One training run: the policy, its optimiser and the environment's current state."""

    def __init__(self, env: VectorEnv, policy: InspectionPolicy, config: TrainConfig):
        self.env, self.policy, self.config = env, policy, config
        self.device = device = policy.log_std.device
        self.optimizer = torch.optim.Adam(policy.parameters(), lr=config.lr, eps=1e-5)
        self.sampler = torch.Generator(device).manual_seed(_torch_seed(config.seed, "actions"))
        self.shuffle = make_rng(config.seed, "learning", "ppo", "minibatches")
        self.scaler = ReturnScaler(config.num_envs, config.gamma)
        self.rollout = Rollout.empty(
            config.rollout_steps, config.num_envs, policy.config.gru_size, device
        )
        self.steps = 0
        self.obstacles: int | None = None
        self._apply_curriculum()
        self.obs, _ = env.reset(seed=config.seed)
        self.hidden = policy.initial_state(config.num_envs)
        self.starts = torch.ones(config.num_envs, device=device)

    def _apply_curriculum(self) -> None:
        count = self.config.obstacles_at(self.steps / self.config.total_steps)
        if count is not None and count != self.obstacles:
            self.env.set_obstacles(count)
            self.obstacles = count

    def collect(self) -> EpisodeStats:
        """Step every env ``rollout_steps`` times, filling :attr:`rollout`."""
        self._apply_curriculum()
        stats, rollout, gamma = EpisodeStats(), self.rollout, self.config.gamma
        rollout.hidden0.copy_(self.hidden)
        for t in range(self.config.rollout_steps):
            obs = as_tensors(self.obs, self.device)
            for key, value in obs.items():
                rollout.obs[key][t].copy_(value)
            sample = self.policy.act(obs, self.hidden, self.starts, generator=self.sampler)
            rollout.starts[t] = self.starts
            rollout.raw_actions[t] = sample.raw_action
            rollout.log_probs[t] = sample.log_prob
            rollout.values[t] = sample.value
            actions = sample.action.cpu().numpy()
            self.obs, reward, terminated, truncated, info = self.env.step(actions)
            done = np.logical_or(terminated, truncated)
            reward = np.asarray(reward, dtype=np.float64)
            if self.config.normalize_rewards:
                reward = self.scaler(reward, done)
            timed_out = np.logical_and(truncated, np.logical_not(terminated))
            if timed_out.any():
                reward[timed_out] += gamma * self._values_of(
                    _final_observations(info, timed_out),
                    sample.hidden[torch.as_tensor(timed_out, device=self.device)],
                )
            rollout.rewards[t] = torch.as_tensor(reward, dtype=torch.float32, device=self.device)
            stats.record(info)
            self.hidden = sample.hidden
            self.starts = torch.as_tensor(done, dtype=torch.float32, device=self.device)
        obs = as_tensors(self.obs, self.device)
        last = self.policy.act(obs, self.hidden, self.starts, deterministic=True)
        rollout.next_value, rollout.next_start = last.value, self.starts.clone()
        self.steps += self.config.steps_per_update
        return stats

    @torch.no_grad()
    def _values_of(self, obs: Mapping[str, np.ndarray], hidden: Tensor) -> np.ndarray:
        """V of observations that end timed-out episodes, continuing their recurrent state."""
        tensors = {key: value.unsqueeze(0) for key, value in as_tensors(obs, self.device).items()}
        out = self.policy(tensors, hidden, torch.zeros(1, hidden.shape[0], device=self.device))
        return out.value[0].cpu().numpy().astype(np.float64)

    def update(self, progress: float) -> dict[str, float]:
        """PPO epochs over minibatches of whole env sequences; the GRU restarts from the state
        stored at the rollout's start and is recomputed through each sequence."""
        config, rollout = self.config, self.rollout
        lr = config.lr * (1.0 - progress) if config.anneal_lr else config.lr
        for group in self.optimizer.param_groups:
            group["lr"] = lr
        advantages, returns = advantages_gae(rollout, config.gamma, config.gae_lambda)
        per_batch = config.num_envs // config.minibatches
        totals: dict[str, list[float]] = {}
        for _ in range(config.epochs):
            order = self.shuffle.permutation(config.num_envs)
            for first in range(0, config.num_envs, per_batch):
                envs = torch.as_tensor(order[first : first + per_batch], device=self.device)
                losses = self._minibatch_step(envs, advantages[:, envs], returns[:, envs])
                for name, value in losses.items():
                    totals.setdefault(name, []).append(value)
        return {name: float(np.mean(values)) for name, values in totals.items()} | {"lr": lr}

    def _minibatch_step(self, envs: Tensor, advantages: Tensor, returns: Tensor) -> dict:
        config, rollout = self.config, self.rollout
        out = self.policy(
            {key: value[:, envs] for key, value in rollout.obs.items()},
            rollout.hidden0[envs],
            rollout.starts[:, envs],
        )
        log_prob = gaussian_log_prob(rollout.raw_actions[:, envs], out.mean, out.log_std)
        log_ratio = log_prob - rollout.log_probs[:, envs]
        ratio = log_ratio.exp()
        advantages = (advantages - advantages.mean()) / (advantages.std() + 1e-8)
        policy_loss = torch.max(
            -advantages * ratio, -advantages * ratio.clamp(1 - config.clip, 1 + config.clip)
        ).mean()
        value_loss = 0.5 * (out.value - returns).pow(2).mean()
        entropy = gaussian_entropy(out.log_std)
        loss = policy_loss + config.vf_coef * value_loss - config.ent_coef * entropy
        self.optimizer.zero_grad()
        loss.backward()
        torch.nn.utils.clip_grad_norm_(self.policy.parameters(), config.max_grad_norm)
        self.optimizer.step()
        with torch.no_grad():
            approx_kl = ((ratio - 1) - log_ratio).mean()
            clipped = ((ratio - 1).abs() > config.clip).float().mean()
        return {
            "policy_loss": policy_loss.item(),
            "value_loss": value_loss.item(),
            "entropy": entropy.item(),
            "approx_kl": approx_kl.item(),
            "clip_fraction": clipped.item(),
        }


# --- logs and checkpoints -------------------------------------------------------------------


class _ProgressLog:
    """``progress.csv`` (rewritten atomically after each update) and, when tensorboardX is
    installed, TensorBoard event files in the same folder."""

    def __init__(self, out_dir: Path):
        self.path = out_dir / "progress.csv"
        self.rows: list[ProgressRow] = []
        try:
            from tensorboardX import SummaryWriter  # noqa: PLC0415 - optional ('rl' extra)
        except ImportError:
            self.writer = None
        else:
            self.writer = SummaryWriter(str(out_dir))

    def add(self, row: ProgressRow) -> None:
        self.rows.append(row)
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        names = [field.name for field in dataclasses.fields(ProgressRow)]
        writer.writerow(names)
        for logged in self.rows:
            writer.writerow(_csv_cell(getattr(logged, name)) for name in names)
        atomic_write_text(self.path, buffer.getvalue())
        if self.writer is not None:
            for name, value in dataclasses.asdict(row).items():
                if name not in {"update", "steps"} and value is not None and math.isfinite(value):
                    self.writer.add_scalar(f"train/{name}", value, row.steps)
            self.writer.flush()

    def close(self) -> None:
        if self.writer is not None:
            self.writer.close()


def _csv_cell(value: float | int | None) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return ""
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def save_checkpoint(
    path: str | Path, policy: InspectionPolicy, train_config: TrainConfig | None, steps: int
) -> Path:
    """Write the policy's weights and configurations atomically."""
    payload = {
        "format": CHECKPOINT_FORMAT,
        "version": CHECKPOINT_VERSION,
        "policy_config": policy.config.model_dump(mode="json"),
        "train_config": None if train_config is None else train_config.model_dump(mode="json"),
        "steps": steps,
        "state_dict": policy.state_dict(),
    }
    return atomic_write_with(path, lambda buffer: torch.save(payload, buffer))


def read_checkpoint(path: str | Path) -> Checkpoint:
    """Load a checkpoint written by :func:`save_checkpoint`; any way it can be missing, broken
    or made for another network is a :class:`FileFormatError` with one line."""
    source = Path(path)
    if not source.is_file():
        reason = "is a directory" if source.is_dir() else "no such file"
        raise FileFormatError(f"{source}: {reason}, expected a policy checkpoint")
    try:
        payload = torch.load(source, map_location="cpu", weights_only=True)
    except (pickle.UnpicklingError, RuntimeError, EOFError, ValueError, zipfile.BadZipFile) as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise FileFormatError(f"{source}: not a readable policy checkpoint ({first})") from None
    if not isinstance(payload, dict) or payload.get("format") != CHECKPOINT_FORMAT:
        raise FileFormatError(f"{source}: not a {CHECKPOINT_FORMAT} checkpoint")
    if payload.get("version") != CHECKPOINT_VERSION:
        raise FileFormatError(
            f"{source}: checkpoint version {payload.get('version')!r} is not supported "
            f"(supported: {CHECKPOINT_VERSION})"
        )
    try:
        policy_config = PolicyConfig.model_validate(payload["policy_config"])
        train = payload.get("train_config")
        train_config = None if train is None else TrainConfig.model_validate(train)
    except ValidationError as exc:
        message = describe_validation_error(exc, "configuration")
        raise FileFormatError(f"{source}: {message}") from None
    policy = InspectionPolicy(policy_config)
    try:
        policy.load_state_dict(payload["state_dict"])
    except (KeyError, RuntimeError, TypeError):
        raise FileFormatError(
            f"{source}: its weights do not fit its policy configuration"
        ) from None
    policy.eval()
    return Checkpoint(policy, policy_config, train_config, int(payload.get("steps", 0)))


def load_policy(path: str | Path) -> InspectionPolicy:
    """The policy of a checkpoint, in evaluation mode."""
    return read_checkpoint(path).policy


# --- the entry point ------------------------------------------------------------------------


def train(
    make_env: Callable[[int, int], VectorEnv],
    policy_config: PolicyConfig,
    train_config: TrainConfig,
    out_dir: str | Path,
    *,
    progress: Callable[[ProgressRow], None] | None = None,
    device: torch.device | str = "cpu",
) -> TrainResult:
    """Train a policy; ``make_env(num_envs, seed)`` builds the vector environment.

    ``device`` holds the network and the rollout ("cuda" for the paper preset where a GPU is
    available); the environment stays on the CPU. Only the CPU is tested here.

    Writes ``progress.csv``, TensorBoard events (with tensorboardX) and ``checkpoint.pt`` into
    ``out_dir``: every ``checkpoint_every`` steps, at the end, and on Ctrl-C or SIGTERM before
    the interruption propagates. The same seed gives the same run.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    checkpoint = out / CHECKPOINT_NAME
    threads = torch.get_num_threads()
    torch.set_num_threads(train_config.threads)
    torch.manual_seed(_torch_seed(train_config.seed, "init"))
    policy = InspectionPolicy(policy_config).to(device)
    env = make_env(train_config.num_envs, train_config.seed)
    log = _ProgressLog(out)
    start = time.perf_counter()
    run = None
    try:
        run = _Run(env, policy, train_config)
        saved_at = 0
        for update in range(1, train_config.updates + 1):
            stats = run.collect()
            losses = run.update((update - 1) / train_config.updates)
            row = _progress_row(update, run, stats, losses, time.perf_counter() - start)
            log.add(row)
            if progress is not None:
                progress(row)
            if run.steps - saved_at >= train_config.checkpoint_every:
                save_checkpoint(checkpoint, policy, train_config, run.steps)
                saved_at = run.steps
        save_checkpoint(checkpoint, policy, train_config, run.steps)
    except KeyboardInterrupt:
        with deferred_signals():  # a second Ctrl-C must not cut the last checkpoint short
            save_checkpoint(checkpoint, policy, train_config, run.steps if run else 0)
        raise
    finally:
        log.close()
        env.close()
        torch.set_num_threads(threads)
    return TrainResult(
        steps=run.steps,
        updates=train_config.updates,
        wall_s=time.perf_counter() - start,
        checkpoint=checkpoint,
        last=log.rows[-1] if log.rows else None,
        tensorboard=log.writer is not None,
    )


def _progress_row(
    update: int, run: _Run, stats: EpisodeStats, losses: dict[str, float], wall_s: float
) -> ProgressRow:
    return ProgressRow(
        update=update,
        steps=run.steps,
        wall_s=wall_s,
        steps_per_s=run.steps / wall_s if wall_s > 0 else math.nan,
        obstacles=run.obstacles,
        episodes=len(stats.returns),
        mean_return=stats.mean(stats.returns),
        coverage_pct=stats.mean(stats.coverage, 100.0),
        crash_pct=stats.mean(stats.crashes, 100.0),
        timeout_pct=stats.mean(stats.timeouts, 100.0),
        **losses,
    )
