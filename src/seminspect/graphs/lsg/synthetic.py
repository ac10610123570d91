"""Synthetic 3DLSGs of any size, built through the same registration operators as a mission.

Vehicles stand on a jittered grid (the area grows with their number, like a city); each is
detected, inspected on ``levels`` levels with ``poses_per_level`` view poses on a ring around it,
and sees a few of its parts per pose. Inspected targets are joined in inspection order and to
their nearest inspected neighbours, as a mission that drives between them would join them. The
graphs feed the planner benchmark, property tests and the shipped example.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from seminspect.core.params import PRESETS, InspectionParams
from seminspect.core.rng import make_rng
from seminspect.core.vocabulary import VEHICLE_PARTS
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.perception.observation import Observation

#: Half-lengths (along x), half-widths (along y) and heights (m) of the synthetic vehicles.
VEHICLE_SIZE = {"car": (2.3, 0.95, 1.5), "truck": (4.0, 1.25, 3.2)}


def synthetic_graph(
    n_targets: int,
    *,
    seed: int = 0,
    poses_per_level: int = 20,
    levels: int = 1,
    parts_per_pose: int = 2,
    spacing: float = 18.0,
    neighbours: int = 2,
    params: InspectionParams | None = None,
) -> LayeredSemanticGraph:
    """A fully inspected graph of ``n_targets`` vehicles (see the module docstring)."""
    rng = make_rng(seed, "synthetic-lsg")
    params = params or PRESETS["urban-simulated"]
    centres, labels = _layout(n_targets, spacing, rng)  # the stream's first draws
    graph = LayeredSemanticGraph(params, robot_position=(0.0, 0.0, 0.0))
    for centre, label in zip(centres, labels, strict=True):
        graph.register_target(
            Observation(
                centre + rng.normal(0, 0.3, 3) * [1, 1, 0],
                label=label,
                score=0.9,
                mask_area=float(rng.uniform(2e3, 4e4)),
            )
        )
    graph.optimise_targets()
    order = _visiting_order(centres)
    targets = graph.targets()
    by_index = {t.index: t for t in targets}
    inspected: list[int] = []
    tree_points: list[np.ndarray] = []
    for k in order:
        target = by_index[k]
        if target.id not in graph:  # pruned by a close neighbour's inspection (eq 10's polygon)
            continue
        _inspect(
            graph,
            target.id,
            centres[k],
            labels[k],
            rng,
            poses_per_level=poses_per_level,
            levels=levels,
            parts_per_pose=parts_per_pose,
        )
        if inspected:
            graph.connect_targets(by_index[inspected[-1]].id, target.id)
            tree = cKDTree(np.asarray(tree_points))
            count = min(neighbours + 1, len(tree_points))
            _, near = tree.query(centres[k][:2], k=count)
            for j in np.atleast_1d(near)[:neighbours]:
                other = by_index[inspected[int(j)]]
                if graph.edge(other.id, target.id) is None:
                    graph.connect_targets(other.id, target.id)
        inspected.append(k)
        tree_points.append(centres[k][:2])
    return graph


def synthetic_layout(
    n_targets: int, *, seed: int = 0, spacing: float = 18.0
) -> tuple[np.ndarray, list[str]]:
    """The vehicle centres (N x 3, 0.75 m up) and labels that :func:`synthetic_graph` places for
    the same arguments: the layout is the first thing drawn from its random stream."""
    return _layout(n_targets, spacing, make_rng(seed, "synthetic-lsg"))


def _layout(n: int, spacing: float, rng: np.random.Generator) -> tuple[np.ndarray, list[str]]:
    columns = max(1, math.ceil(math.sqrt(n * 1.5)))
    cells = np.arange(n)
    xy = np.stack([cells % columns, cells // columns], axis=1) * spacing
    xy = xy + rng.uniform(-0.15, 0.15, (n, 2)) * spacing + spacing
    centres = np.column_stack([xy, np.full(n, 0.75)])
    labels = ["truck" if u < 0.3 else "car" for u in rng.uniform(size=n)]
    return centres, labels


def _visiting_order(centres: np.ndarray) -> list[int]:
    """Greedy nearest-neighbour tour from the origin, like a robot picking the closest target."""
    remaining = set(range(len(centres)))
    tree = cKDTree(centres[:, :2])
    here = np.zeros(2)
    order: list[int] = []
    while remaining:
        k = min(len(centres), 8)
        while True:
            _, idx = tree.query(here, k=k)
            free = [int(i) for i in np.atleast_1d(idx) if int(i) in remaining]
            if free or k >= len(centres):
                break
            k = min(len(centres), k * 4)
        nxt = free[0] if free else min(remaining)
        order.append(nxt)
        remaining.discard(nxt)
        here = centres[nxt, :2]
    return order


def _inspect(
    graph: LayeredSemanticGraph,
    target_id: str,
    centre: np.ndarray,
    label: str,
    rng: np.random.Generator,
    *,
    poses_per_level: int,
    levels: int,
    parts_per_pose: int,
) -> None:
    half_length, half_width, height = VEHICLE_SIZE[label]
    radius = math.hypot(half_length, half_width) + 2.5
    start_angle = float(rng.uniform(0, math.tau))
    for level in range(levels):
        z = 0.7 + 3.0 * level
        entry = centre[:2] + radius * np.array([math.cos(start_angle), math.sin(start_angle)])
        entry_obs = Observation.view_pose(
            [entry[0], entry[1], z], quat_from_yaw(start_angle + math.pi)
        )
        if level == 0:
            graph.begin_inspection(target_id, entry_obs)
        else:
            graph.begin_level(entry_obs)
        for n in range(poses_per_level):
            angle = start_angle + math.tau * (n + 1) / (poses_per_level + 1)
            xy = centre[:2] + radius * np.array([math.cos(angle), math.sin(angle)])
            graph.register_pose(
                Observation.view_pose(
                    [xy[0], xy[1], z],
                    quat_from_yaw(angle + math.pi),
                    image=f"{target_id}/L{level}/{n:03d}.png",
                )
            )
            for part in rng.choice(len(VEHICLE_PARTS), size=parts_per_pose, replace=False):
                offset = rng.uniform(-1, 1, 3) * [half_length, half_width, 0.5 * height]
                graph.register_feature(
                    Observation(
                        centre + offset + [0, 0, 0.5 * height - 0.75],
                        label=VEHICLE_PARTS[int(part)],
                        score=float(rng.uniform(0.5, 1.0)),
                        mask_area=float(rng.uniform(500, 8000)),
                    )
                )
    graph.finish_inspection()
