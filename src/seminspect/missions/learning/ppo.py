"""Recurrent PPO for the inspection policy of 004: the training loop, read top to bottom.

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

So the algorithm lives here in a few hundred lines: the collection of rollouts and the PPO
update below, the rollout storage and GAE in :mod:`.rollout`, the hyper-parameters in
:class:`~.train_config.TrainConfig`, checkpoints in :mod:`.checkpoints` and the logs in
:mod:`.progress`.

Other choices: a truncated episode (the paper's "timeout", the usual end) is bootstrapped with
the value of its last observation rather than treated as terminal; rewards may be scaled by a
running standard deviation of the discounted return; obstacles enter by a curriculum (004 trains
with nine obstacles and sets up a curriculum without giving its schedule: ours steps through
obstacle counts at fractions of the training, 0, 4 then 9 by default).

A run trains in pieces: :func:`train` starts one and :func:`resume` continues it from its
``training-state.pt`` (:mod:`.training_state`), saved only at update boundaries (a stop signal
waits for the update under way to end) and continued bit for bit.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Protocol

import numpy as np
import torch
from torch import Tensor

from seminspect.core.errors import InvalidInputError
from seminspect.core.interrupts import deferred_signals, stop_on_signals
from seminspect.core.rng import make_rng
from seminspect.core.torch_files import torch_threads
from seminspect.missions.learning.checkpoints import CHECKPOINT_NAME, save_checkpoint
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.policy import (
    InspectionPolicy,
    PolicyConfig,
    as_tensors,
    gaussian_entropy,
    gaussian_log_prob,
)
from seminspect.missions.learning.progress import EpisodeStats, ProgressLog, ProgressRow
from seminspect.missions.learning.rollout import (
    ReturnScaler,
    Rollout,
    advantages_gae,
    final_observations,
)
from seminspect.missions.learning.train_config import TrainConfig
from seminspect.missions.learning.training_state import (
    TRAINING_STATE_NAME,
    TrainingState,
    save_training_state,
)


class VectorEnv(Protocol):
    """What the trainer needs of an environment (the contract of ``learning.env``)."""

    num_envs: int

    def reset(self, *, seed: int | None = None) -> tuple[dict[str, np.ndarray], dict]: ...

    def step(
        self, actions: np.ndarray
    ) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray, np.ndarray, dict]: ...

    def set_obstacles(self, counts: int) -> None: ...

    def close(self) -> None: ...


@dataclasses.dataclass(frozen=True)
class TrainResult:
    """What :func:`train` leaves behind."""

    steps: int
    updates: int  # done, all pieces of the run together
    wall_s: float  # of this piece
    checkpoint: Path
    last: ProgressRow | None
    tensorboard: bool  # whether event files were written
    finished: bool  # False: stopped by its time limit; resume() continues it


def _torch_seed(seed: int, stream: str) -> int:
    return int(make_rng(seed, "learning", "ppo", stream).integers(2**62))


class _Run:
    """One training run: the policy, its optimiser and the environment's current state."""

    def __init__(
        self, env: VectorEnv, policy: InspectionPolicy, config: TrainConfig, env_config: EnvConfig
    ):
        self.env, self.policy, self.config, self.env_config = env, policy, config, env_config
        self.device = device = policy.log_std.device
        self.optimizer = torch.optim.Adam(policy.parameters(), lr=config.lr, eps=1e-5)
        self.sampler = torch.Generator(device).manual_seed(_torch_seed(config.seed, "actions"))
        self.shuffle = make_rng(config.seed, "learning", "ppo", "minibatches")
        self.scaler = ReturnScaler(config.num_envs, config.gamma)
        self.rollout = Rollout.empty(
            config.rollout_steps, config.num_envs, policy.config.gru_size, device
        )
        self.updates = self.steps = self.saved_at = 0
        self.wall_s = 0.0  # training time up to the last update's end, all pieces together
        self.obstacles: int | None = None
        self.hidden = policy.initial_state(config.num_envs)
        self.starts = torch.ones(config.num_envs, device=device)
        self.obs: dict[str, np.ndarray] = {}
        self.whole = False  # True at an update boundary: only then may the state be saved

    def begin(self) -> None:
        """Reset the env into the first rooms of a new run."""
        self._apply_curriculum()
        self.obs, _ = self.env.reset(seed=self.config.seed)
        self.whole = True

    def state(self, rows: tuple[ProgressRow, ...]) -> TrainingState:
        """Everything that moves a number of the updates to come (at an update boundary)."""
        run = {
            "policy": self.policy.state_dict(),
            "optimizer": self.optimizer.state_dict(),
            "sampler": self.sampler.get_state(),
            "torch_rng": torch.get_rng_state(),
            "shuffle": self.shuffle.bit_generator.state,
            "scaler": dict(vars(self.scaler)),
            "saved_at": self.saved_at,
            "wall_s": self.wall_s,
            "obstacles": self.obstacles,
            "hidden": self.hidden,
            "starts": self.starts,
            "obs": self.obs,
            "env": self.env,
        }
        return TrainingState(
            self.policy.config,
            self.config,
            self.env_config,
            str(self.device),
            self.updates,
            self.steps,
            rows,
            run,
        )

    @classmethod
    def restored(cls, state: TrainingState) -> _Run:
        """The run :meth:`state` saved, on the device it trained on."""
        saved = state.run
        policy = InspectionPolicy(state.policy_config).to(state.device)
        policy.load_state_dict(saved["policy"])
        run = cls(saved["env"], policy, state.train_config, state.env_config)
        run.optimizer.load_state_dict(saved["optimizer"])
        run.sampler.set_state(saved["sampler"])
        torch.set_rng_state(saved["torch_rng"])
        run.shuffle.bit_generator.state = saved["shuffle"]
        vars(run.scaler).update(saved["scaler"])
        run.updates, run.steps = state.updates, state.steps
        run.saved_at, run.wall_s, run.obstacles = (
            saved["saved_at"],
            saved["wall_s"],
            saved["obstacles"],
        )
        run.hidden = saved["hidden"].to(run.device)
        run.starts = saved["starts"].to(run.device)
        run.obs = saved["obs"]
        run.whole = True
        return run

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
                    final_observations(info, timed_out),
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


# --- the entry points -----------------------------------------------------------------------


def train(
    make_env: Callable[[int, int], VectorEnv],
    policy_config: PolicyConfig,
    train_config: TrainConfig,
    out_dir: str | Path,
    *,
    env_config: EnvConfig,
    progress: Callable[[ProgressRow], None] | None = None,
    device: torch.device | str = "cpu",
    stop_after_s: float | None = None,
    initial: InspectionPolicy | None = None,
) -> TrainResult:
    """Train a policy; ``make_env(num_envs, seed)`` builds the vector environment, whose
    settings ``env_config`` names (each checkpoint records them). ``initial``: a policy of
    ``policy_config`` whose weights the run starts from (a fine-tune; ``train_config.init_from``
    names its checkpoint), else fresh ones.

    ``device`` holds the network and the rollout ("cuda" for the paper preset where a GPU is
    available); the environment stays on the CPU. Only the CPU is tested here.

    Writes ``progress.csv``, TensorBoard events (with tensorboardX), ``checkpoint.pt`` and
    ``training-state.pt`` into ``out_dir``: every ``checkpoint_every`` steps, at the end, at
    the first update boundary after ``stop_after_s`` seconds (then :func:`resume` continues),
    and on Ctrl-C or SIGTERM before the interruption propagates. The same seed gives the same
    run.
    """
    shaping = env_config.shaping_discount
    if shaping is not None and shaping != train_config.gamma:
        raise InvalidInputError(
            f"the env shapes its reward for discount {shaping} but PPO discounts by "
            f"{train_config.gamma}: shaping leaves the best policy unchanged only with one"
        )
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    with torch_threads(train_config.threads):
        torch.manual_seed(_torch_seed(train_config.seed, "init"))
        policy = InspectionPolicy(policy_config).to(device)
        if initial is not None:
            if initial.config != policy_config:
                raise InvalidInputError("the initial policy is another network than the run's")
            policy.load_state_dict(initial.state_dict())
        env = make_env(train_config.num_envs, train_config.seed)
        run = _Run(env, policy, train_config, env_config)
        return _drive(run, out, ProgressLog(out), progress, stop_after_s)


def resume(
    state: TrainingState,
    out_dir: str | Path,
    *,
    progress: Callable[[ProgressRow], None] | None = None,
    stop_after_s: float | None = None,
) -> TrainResult:
    """Continue the run ``state`` saved (:func:`~.training_state.read_training_state` of
    ``out_dir``), as if it had never stopped; ``progress.csv`` goes on from its rows."""
    out = Path(out_dir)
    with torch_threads(state.train_config.threads):
        run = _Run.restored(state)
        return _drive(run, out, ProgressLog(out, state.rows), progress, stop_after_s)


def _drive(
    run: _Run,
    out: Path,
    log: ProgressLog,
    progress: Callable[[ProgressRow], None] | None,
    stop_after_s: float | None,
) -> TrainResult:
    """Run updates to the budget or the time limit, saving as :func:`train` says."""
    start = time.perf_counter()
    with stop_on_signals():  # SIGTERM as Ctrl-C, and both held back until an update's end
        try:
            if not run.whole:
                run.begin()
            finished = _updates(run, out, log, progress, start=start, stop_after_s=stop_after_s)
            _save(run, out, log)
        except KeyboardInterrupt:
            if run.whole:  # else the last saved state stays: it is the last whole one
                _save(run, out, log)
            raise
        finally:
            log.close()
            run.env.close()
    return TrainResult(
        steps=run.steps,
        updates=run.updates,
        wall_s=time.perf_counter() - start,
        checkpoint=out / CHECKPOINT_NAME,
        last=log.rows[-1] if log.rows else None,
        tensorboard=log.writer is not None,
        finished=finished,
    )


def _updates(
    run: _Run,
    out: Path,
    log: ProgressLog,
    progress: Callable[[ProgressRow], None] | None,
    *,
    start: float,
    stop_after_s: float | None,
) -> bool:
    """Updates until the budget is spent (True) or ``stop_after_s`` has passed (False)."""
    config, before = run.config, run.wall_s
    while run.updates < config.updates:
        with deferred_signals():  # a stop signal waits for the boundary, where the state is whole
            run.whole = False
            stats = run.collect()
            losses = run.update(run.updates / config.updates)
            run.updates += 1
            run.wall_s = before + time.perf_counter() - start
            row = _progress_row(run, stats, losses)
            log.add(row)
            run.whole = True
        if progress is not None:
            progress(row)
        if run.steps - run.saved_at >= config.checkpoint_every:
            _save(run, out, log)
        if stop_after_s is not None and time.perf_counter() - start >= stop_after_s:
            return run.updates >= config.updates
    return True


def _save(run: _Run, out: Path, log: ProgressLog) -> None:
    """The training state and the checkpoint, at an update boundary."""
    with deferred_signals():  # a second Ctrl-C must not cut the last save short
        run.saved_at = run.steps
        save_training_state(out / TRAINING_STATE_NAME, run.state(tuple(log.rows)))
        save_checkpoint(out / CHECKPOINT_NAME, run.policy, run.config, run.steps, run.env_config)


def _progress_row(run: _Run, stats: EpisodeStats, losses: dict[str, float]) -> ProgressRow:
    wall_s = run.wall_s
    return ProgressRow(
        update=run.updates,
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
