"""Inference time and checkpoint size of the 004 policy presets on one CPU thread.

For ``PolicyConfig.small()`` and ``PolicyConfig.paper()`` (004 Sec III-D): the time of one
``act`` call (encoders, MLP, GRU, heads, a sampled action) for a batch of 64 environments (one
vector-env step of training) and for one robot (the onboard case, against the paper's 100 ms
per step on a Jetson), the time of one PPO minibatch pass (forward and backward through a
32-step sequence of 16 envs), the parameter count and the size of a saved checkpoint.
Times are medians of repeated calls on one torch thread, each preset measured in turn.

Run: ``.venv/bin/python bench/rl_policy.py`` (``--repeats N``, ``--json out.json``).
"""

from __future__ import annotations

import argparse
import functools
import statistics
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import torch

from seminspect.core.io import atomic_write_text, dumps_json
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.policy import (
    DEPTH_SHAPE,
    MAPS_SHAPE,
    STATE_SIZE,
    InspectionPolicy,
    PolicyConfig,
)
from seminspect.missions.learning.ppo import save_checkpoint

PAPER_ONBOARD_MS = 100.0  # 004: one inference step on the robot's Jetson


def observations(steps: int, batch: int) -> dict[str, torch.Tensor]:
    generator = torch.Generator().manual_seed(0)
    return {
        "state": torch.rand(steps, batch, STATE_SIZE, generator=generator),
        "depth": torch.rand(steps, batch, *DEPTH_SHAPE, generator=generator),
        "maps": (torch.rand(steps, batch, *MAPS_SHAPE, generator=generator) > 0.9).float(),
    }


def median_ms(call: Callable[[], object], repeats: int) -> float:
    call()  # first call allocates
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return 1e3 * statistics.median(times)


def measure(name: str, config: PolicyConfig, repeats: int) -> dict[str, float | str]:
    torch.manual_seed(0)
    policy = InspectionPolicy(config)
    figures: dict[str, float | str] = {"preset": name}
    figures["parameters"] = sum(p.numel() for p in policy.parameters())
    for batch in (64, 1):
        obs = {key: value[0] for key, value in observations(1, batch).items()}
        hidden = policy.initial_state(batch)
        act = functools.partial(policy.act, obs, hidden)
        figures[f"act_b{batch}_ms"] = median_ms(act, repeats)

    sequence = observations(32, 16)
    starts = torch.zeros(32, 16)

    def minibatch() -> None:
        out = policy(sequence, policy.initial_state(16), starts)
        (out.mean.square().mean() + out.value.square().mean()).backward()

    figures["minibatch_32x16_ms"] = median_ms(minibatch, max(1, repeats // 5))
    with tempfile.TemporaryDirectory() as folder:
        path = save_checkpoint(Path(folder) / "checkpoint.pt", policy, None, 0, EnvConfig())
        figures["checkpoint_mb"] = path.stat().st_size / 1e6
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    torch.set_num_threads(1)
    rows = [
        measure("small", PolicyConfig.small(), args.repeats),
        measure("paper", PolicyConfig.paper(), max(3, args.repeats // 4)),
    ]
    print(f"torch {torch.__version__}, {torch.get_num_threads()} thread")
    header = "preset  params      act b=64  act b=1  vs 100 ms  minibatch 32x16  checkpoint"
    print(header)
    for row in rows:
        print(
            f"{row['preset']:<7} {row['parameters']:>10,}  {row['act_b64_ms']:7.2f} ms"
            f" {row['act_b1_ms']:6.2f} ms  {PAPER_ONBOARD_MS / row['act_b1_ms']:7.0f}x"
            f"  {row['minibatch_32x16_ms']:12.1f} ms  {row['checkpoint_mb']:7.2f} MB"
        )
    if args.json:
        atomic_write_text(args.json, dumps_json(rows, indent=2) + "\n")


if __name__ == "__main__":
    main()
