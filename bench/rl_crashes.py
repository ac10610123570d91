"""Why a learned 004 policy crashes: what it struck, how fast, and whether its map showed it.

Flies a checkpoint through the evaluation protocol's rooms (seed 0, the batches of
``missions.learning.evaluation``) and, for every crash, reads the step before it: the surface
struck (:func:`~seminspect.missions.learning.rooms.struck_surface`), the speed, the coverage
reached, and whether the ego occupancy map m^o the policy saw marked the struck surface as
occupied (a cell within one cell of the nearest surface point). Over
every room it also counts the steps flown inside the proximity penalty's d_coll, where the
policy is paid -1 a step for its nearness.

A crash with the surface mapped is the policy's choice, not a blind spot of its sensors.

Run: ``.venv/bin/python bench/rl_crashes.py [--policy CHECKPOINT] [--obstacles 9] [--rooms 100]``
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.geometry.transforms import body_from_world
from seminspect.missions.learning.agent import load_controller
from seminspect.missions.learning.baselines import Controller
from seminspect.missions.learning.env import InspectionVectorEnv
from seminspect.missions.learning.evaluation import batch_seed, controller_evaluation_config
from seminspect.missions.learning.maps import ego_offsets
from seminspect.missions.learning.rooms import Room, clearance, stack_solids, struck_surface

SEED, BATCH_ROOMS = 0, 50


def nearest_surface_offset(room: Room, point: NDArray[np.float64]) -> NDArray[np.float64]:
    """World-frame offset from ``point`` to the nearest surface of ``room`` (walls included),
    along the clearance field's gradient (central differences, 1 mm)."""
    probes = point + np.concatenate([np.eye(3), -np.eye(3)]) * 1e-3
    values = clearance(probes, room.solids, room.size)
    gradient = (values[:3] - values[3:]) / 2e-3
    gap = clearance(point[None], room.solids, room.size)[0]
    return -gap * gradient / max(float(np.linalg.norm(gradient)), 1e-9)


def mapped_occupied(
    occupancy: NDArray[np.float32], offset_body: NDArray[np.float64], resolution: float
) -> bool:
    """Whether the ego map marks occupied a cell within one cell of ``offset_body`` (the
    nearest surface point, body frame): the surface was on the map the policy saw."""
    centres = ego_offsets(occupancy.shape[0], resolution)
    around = np.abs(centres - offset_body).max(axis=1) <= 1.5 * resolution
    return bool((occupancy.reshape(-1)[around] == 1.0).any())


def fly_batch(controller: Controller, obstacles: int, batch: int, rooms: int) -> dict:
    """One batch of the protocol's rooms: its crashes, and steps flown and inside d_coll."""
    config = controller_evaluation_config(controller).model_copy(update={"obstacles": obstacles})
    env = InspectionVectorEnv(rooms, config, autoreset=False)
    obs, _ = env.reset(seed=batch_seed(SEED, obstacles, batch))
    controller.reset(env)
    done = np.zeros(rooms, dtype=bool)
    solids, sizes = stack_solids(env.rooms), np.array([room.size for room in env.rooms])
    crashes, steps, near = [], 0, 0
    for step in range(1, config.steps_per_episode + 1):
        before, yaw, occupancy = env.positions(), env.yaws(), obs["maps"][:, 0].copy()
        gaps = clearance(before, solids, sizes)
        steps += int((~done).sum())
        near += int(((gaps < config.d_coll) & ~done).sum())
        obs, _, crash, timeout, _ = env.step(controller.act(env, obs))
        after = env.positions()
        for e in np.flatnonzero(crash):
            offset = nearest_surface_offset(env.rooms[e], before[e])
            crashes.append({
                "time_s": step / config.control_hz,
                "struck": struck_surface(env.rooms[e], after[e]),
                "speed": float(np.linalg.norm(after[e] - before[e]) * config.control_hz),
                "coverage": float(env.coverage()[e] * 100.0),
                "mapped": mapped_occupied(
                    occupancy[e], body_from_world(offset[None], yaw[e:e + 1])[0],
                    config.map_resolution,
                ),
            })  # fmt: skip
        done |= crash | timeout
        if done.all():
            break
    return {"crashes": crashes, "steps": steps, "near": near}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--policy", type=Path, help="checkpoint file (default: the shipped one)")
    parser.add_argument("--obstacles", type=int, default=9)
    parser.add_argument("--rooms", type=int, default=100, help="the protocol's first N rooms")
    args = parser.parse_args()
    try:
        if args.rooms < 1 or args.obstacles < 0:
            raise InvalidInputError("--rooms must be at least 1 and --obstacles at least 0")
        controller = load_controller(args.policy)
    except (InvalidInputError, FileFormatError) as exc:
        sys.exit(f"error: {exc}")
    crashes, steps, near = [], 0, 0
    for batch, first in enumerate(range(0, args.rooms, BATCH_ROOMS)):
        flown = fly_batch(controller, args.obstacles, batch, min(BATCH_ROOMS, args.rooms - first))
        crashes += flown["crashes"]
        steps, near = steps + flown["steps"], near + flown["near"]
    for crash in crashes:
        print(f"t {crash['time_s']:5.1f} s  struck {crash['struck']:<8}  "
              f"speed {crash['speed']:.2f} m/s  coverage {crash['coverage']:5.1f} %  "
              f"{'mapped' if crash['mapped'] else 'NOT mapped'}")  # fmt: skip
    struck = Counter(c["struck"] for c in crashes)
    print(
        f"\n{len(crashes)} crashes in {args.rooms} rooms at {args.obstacles} obstacles; struck: "
        + ", ".join(f"{name} {count}" for name, count in struck.most_common())
    )
    if crashes:
        mapped = sum(c["mapped"] for c in crashes)
        print(
            f"struck surface mapped occupied the step before: {mapped} of {len(crashes)}; "
            f"median speed {np.median([c['speed'] for c in crashes]):.2f} m/s, median "
            f"coverage {np.median([c['coverage'] for c in crashes]):.0f} %, median time "
            f"{np.median([c['time_s'] for c in crashes]):.0f} s"
        )
    print(f"steps inside d_coll: {100.0 * near / max(steps, 1):.1f} % of {steps} room-steps")


if __name__ == "__main__":
    main()
