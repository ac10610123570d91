"""Grid planning benchmark: the volumetric baseline's engines and the mission's local planner.

Synthetic city blocks of 150 m x 100 m x 5 m (buildings as tall boxes, cars and trucks as small
boxes on the streets) are voxelised at 0.4, 0.5 and 0.7 m (000 Sec VII-C/D). Each query starts
at a random free point 1-2 m above the ground and goes to a random vehicle, stopping within the
arrival radius epsilon = 2 m of its centre (000 Table 1), like the paper's "Visit ..." queries.
Every engine answers the same queries on the same costs; the benchmark checks they agree on the
optimal cost before printing times.

The local planner is measured on the robot's partial map of the same city at 0.2 and 0.4 m:
cells the robot has not seen yet are unknown and crossable at an extra cost.

    .venv/bin/python bench/grid_planning.py [--queries 12] [--seed 0] [--quick]
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import statistics
import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from seminspect.core.rng import make_rng
from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN, VoxelMap
from seminspect.planning.gridmap import CostModel
from seminspect.planning.routes import LocalPlanner
from seminspect.planning.smoothing import refine_path, voxel_segment_checker
from seminspect.planning.volumetric import ENGINES, VolumetricPlanner

SIZE = (150.0, 100.0, 5.0)
ROBOT_RADIUS = 0.4
ARRIVAL_RADIUS = 2.0  # 000 Table 1, epsilon


@dataclass(frozen=True)
class City:
    buildings: NDArray[np.float64]  # (B, 2, 3) lower / upper corners
    vehicles: NDArray[np.float64]  # (V, 2, 3)


def make_city(seed: int) -> City:
    """Blocks of buildings on a street grid, vehicles parked along the streets."""
    rng = make_rng(seed, "bench", "city")
    buildings, vehicles = [], []
    for x0 in np.arange(5.0, SIZE[0] - 20.0, 30.0):
        for y0 in np.arange(5.0, SIZE[1] - 15.0, 25.0):
            w, d = rng.uniform(10.0, 20.0), rng.uniform(8.0, 15.0)
            buildings.append([[x0, y0, 0.0], [x0 + w, y0 + d, 8.0]])
            for _ in range(3):  # vehicles on the street east / north of the block
                car = rng.random() < 0.7
                length, width, height = (4.5, 2.0, 1.6) if car else (10.0, 2.5, 3.4)
                if rng.random() < 0.5:
                    x, y = x0 + w + rng.uniform(1.5, 6.0), y0 + rng.uniform(0.0, d)
                    box = [[x, y, 0.0], [x + width, y + length, height]]
                else:
                    x, y = x0 + rng.uniform(0.0, w), y0 + d + rng.uniform(1.5, 6.0)
                    box = [[x, y, 0.0], [x + length, y + width, height]]
                vehicles.append(box)
    return City(np.array(buildings), np.clip(np.array(vehicles), 0.0, SIZE))


def voxelise(city: City, resolution: float) -> VoxelMap:
    """A fully known map: a voxel is occupied when it overlaps a box."""
    grid = VoxelMap.empty([0.0, 0.0, 0.0], SIZE, resolution)
    grid.states[:] = FREE
    for lo, hi in np.concatenate([city.buildings, city.vehicles]):
        a = np.clip(np.floor(lo / resolution).astype(int), 0, grid.shape)
        b = np.clip(np.ceil(hi / resolution).astype(int), 0, grid.shape)
        grid.states[a[0] : b[0], a[1] : b[1], a[2] : b[2]] = OCCUPIED
    return grid


def partial_map(full: VoxelMap, seed: int) -> VoxelMap:
    """The robot's view: known within 25 m of a few survey points, unknown elsewhere."""
    rng = make_rng(seed, "bench", "survey")
    centres = full.index_to_world(np.indices((*full.shape[:2], 1)).reshape(3, -1).T)[:, :2]
    seen = np.zeros(len(centres), dtype=bool)
    for point in rng.uniform([0, 0], SIZE[:2], size=(6, 2)):
        seen |= np.linalg.norm(centres - point, axis=1) < 25.0
    known = seen.reshape(full.shape[:2])
    states = np.where(known[:, :, None], full.states, UNKNOWN).astype(np.uint8)
    return VoxelMap(full.origin, full.resolution, states)


def queries(
    city: City, planner: VolumetricPlanner, count: int, seed: int
) -> list[tuple[NDArray, NDArray]]:
    """Random free starts paired with random vehicles at least 30 m away."""
    rng = make_rng(seed, "bench", "queries")
    found: list[tuple[NDArray, NDArray]] = []
    while len(found) < count:
        start = rng.uniform([1.0, 1.0, 1.0], [SIZE[0] - 1.0, SIZE[1] - 1.0, 2.0])
        cell = planner.grid.cell_of(start, "start")
        if not math.isfinite(planner.grid.costs_of(cell)):
            continue
        lo, hi = city.vehicles[rng.integers(len(city.vehicles))]
        goal = (lo + hi) / 2
        if np.linalg.norm(goal - start) >= 30.0:
            found.append((start, goal))
    return found


def _engine_planners(voxels: VoxelMap, engines: tuple[str, ...]) -> dict[str, object]:
    model = CostModel(ROBOT_RADIUS)
    planners: dict[str, object] = {e: VolumetricPlanner(voxels, model, engine=e) for e in engines}
    if importlib.util.find_spec("ompl") is not None:
        from seminspect.planning.ompl_planner import OmplPlanner

        planners["ompl-rrtconnect"] = OmplPlanner(voxels, model, seed=0)
    return planners


def bench_engines(city: City, count: int, seed: int, engines: tuple[str, ...]) -> None:
    print(f"\n## Volumetric baseline, {count} queries per resolution")
    print(
        "| res m | engine | build s | median ms | max ms | x A* | median expansions | length / A* |"
    )
    print("|---|---|---|---|---|---|---|---|")
    summary = []
    for res in (0.4, 0.5, 0.7):
        voxels = voxelise(city, res)
        planners = _engine_planners(voxels, engines)
        pairs = queries(city, planners["astar"], count, seed)
        results: dict[str, list] = {}
        for name, planner in planners.items():
            planner.plan(*pairs[0], ARRIVAL_RADIUS)  # compile / warm up outside the timing
            results[name] = [planner.plan(s, g, ARRIVAL_RADIUS) for s, g in pairs]
        best = results["astar"]
        for name in engines:
            costs = [p.cost for p in results[name]]
            assert np.allclose(costs, [p.cost for p in best], rtol=1e-6), f"{name} != A*"
        base_ms = statistics.median(1e3 * p.planning_time for p in best)
        for name, paths in results.items():
            times = [1e3 * p.planning_time for p in paths]
            ratio = statistics.median(p.length / b.length for p, b in zip(paths, best, strict=True))
            print(
                f"| {res} | {name} | {planners[name].build_time:.2f} | "
                f"{statistics.median(times):.1f} | {max(times):.1f} | "
                f"{statistics.median(times) / base_ms:.1f} | "
                f"{statistics.median(p.expansions for p in paths):.0f} | {ratio:.3f} |"
            )
        summary.append(refinement_row(res, voxels, best))
    print("\n## A* paths before and after shortcutting (robot radius clearance)")
    print("| res m | cells | A* length m (median, range) | refined / raw length | refine ms |")
    print("|---|---|---|---|---|")
    print("\n".join(summary))


def refinement_row(res: float, voxels: VoxelMap, paths: list) -> str:
    check = voxel_segment_checker(voxels, ROBOT_RADIUS)
    refined = [refine_path(p.waypoints, check) for p in paths]
    lengths = [p.length for p in paths]
    gain = statistics.mean(r.refined_length / r.raw_length for r in refined)
    ms = statistics.median(1e3 * r.refine_time for r in refined)
    return (
        f"| {res} | {voxels.states.size:,} | {statistics.median(lengths):.1f} "
        f"({min(lengths):.0f}-{max(lengths):.0f}) | {gain:.3f} | {ms:.1f} |"
    )


def _legs(city: City, full: VoxelMap, count: int, seed: int) -> list[tuple[NDArray, NDArray]]:
    """Start / goal pairs 30-80 m apart, both free in the true map, 1 m above the ground."""
    truth = VolumetricPlanner(full, CostModel(ROBOT_RADIUS)).grid
    rng = make_rng(seed, "bench", "legs")
    legs: list[tuple[NDArray, NDArray]] = []
    while len(legs) < count:
        a, b = rng.uniform([1.0, 1.0, 1.0], [SIZE[0] - 1.0, SIZE[1] - 1.0, 1.0], (2, 3))
        free = all(math.isfinite(truth.costs_of(truth.cell_of(p, "p"))) for p in (a, b))
        if free and 30.0 <= np.linalg.norm(a - b) <= 80.0:
            legs.append((a, b))
    return legs


def bench_local(city: City, count: int, seed: int) -> None:
    print(f"\n## Local planner on the robot's partial map, {count} legs of 30-80 m")
    print(
        "| mode | res m | cells | weight | median ms | max ms | median expansions | cost / optimal "
        "| length / optimal | waypoints |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    model = CostModel(ROBOT_RADIUS, unknown_cost=1.0)
    for res in (0.2, 0.4):
        full = voxelise(city, res)
        robot_map = partial_map(full, seed)
        legs = _legs(city, full, count, seed)
        for mode in ("ground", "aerial"):
            optimal = None
            for weight in (1.0, 2.0):
                planner = LocalPlanner(model, mode=mode, band=(0.3, 1.5), heuristic_weight=weight)
                planner.plan(robot_map, *legs[0])  # compile outside the timing
                paths = [planner.plan(robot_map, a, b) for a, b in legs]
                optimal = optimal or paths
                times = [1e3 * p.planning_time for p in paths]
                pairs = list(zip(paths, optimal, strict=True))
                print(
                    f"| {mode} | {res} | {robot_map.states.size:,} | {weight:g} | "
                    f"{statistics.median(times):.1f} | {max(times):.1f} | "
                    f"{statistics.median(p.expansions for p in paths):.0f} | "
                    f"{statistics.mean(p.cost / o.cost for p, o in pairs):.3f} | "
                    f"{statistics.mean(p.length / o.length for p, o in pairs):.3f} | "
                    f"{statistics.median(len(p.waypoints) for p in paths):.0f} |"
                )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--queries", type=int, default=12)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--quick", action="store_true", help="skip the slow csgraph engine")
    args = parser.parse_args()
    city = make_city(args.seed)
    print(f"city: {len(city.buildings)} buildings, {len(city.vehicles)} vehicles")
    t0 = time.perf_counter()
    engines = tuple(e for e in ENGINES if not (args.quick and e == "csgraph"))
    bench_engines(city, args.queries, args.seed, engines)
    bench_local(city, args.queries, args.seed)
    print(f"\ntotal {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
