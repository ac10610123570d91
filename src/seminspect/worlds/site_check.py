"""What ``seminspect world check`` says about a world before any mission: what is missing or
odd in a site, with a level for each finding (an error makes the check fail).

Errors: nothing to inspect, a start outside the bounds, off the ground or inside an obstacle,
objects that overlap. Warnings: targets without parts, target parts outside the built-in
vocabulary (used as custom features), an object whose long axis lies across the heading its
site gives it (its ``forward:`` is probably wrong).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import combinations
from typing import Literal

import numpy as np

from seminspect.core.vocabulary import KNOWN_FEATURES, STRUCTURE_PARTS
from seminspect.worlds.pieces import heading_of, object_vertices
from seminspect.worlds.world import InstanceInfo, World

#: Part names the built-in targets carry: the object itself (body, roof, wall) and the
#: built-in inspection features.
KNOWN_PARTS = frozenset(STRUCTURE_PARTS + KNOWN_FEATURES)
#: The robot a check assumes: a ground robot of the default body radius (``robot.Robot``).
ROBOT_RADIUS = 0.4
#: How far (m) a start may lie off the ground.
GROUND_TOLERANCE = 1e-3
#: Footprints overlapping by more than this (m^2) are two objects in one place.
OVERLAP_M2 = 0.05
#: An object this much longer than wide has a long axis to compare with its heading.
ELONGATION = 1.25


@dataclass(frozen=True)
class Finding:
    level: Literal["error", "warning"]
    message: str


def check_world(
    world: World, target_classes: Sequence[str], radius: float = ROBOT_RADIUS
) -> list[Finding]:
    """Every finding about ``world`` for a mission inspecting ``target_classes``."""
    findings = _targets(world, target_classes) + _start(world, radius)
    for info in world.instances.values():
        findings += _facing(world, info)
    for info in world.instances_of(*target_classes):
        findings += _parts(info)
    return findings + _overlaps(world)


def _targets(world: World, classes: Sequence[str]) -> list[Finding]:
    if world.instances_of(*classes):
        return []
    found = sorted({info.class_name for info in world.instances.values()})
    holds = f"it holds only {', '.join(found)}" if found else "it holds no objects"
    return [
        Finding(
            "error", f"no targets ({', '.join(classes)}): {holds}; a mission would only explore"
        )
    ]


def _start(world: World, radius: float) -> list[Finding]:
    start = world.start_position
    lo, hi = world.bounds
    where = f"start {np.round(start, 2).tolist()}"
    if np.any((start[:2] < lo[:2]) | (start[:2] > hi[:2])):
        return [
            Finding(
                "error",
                f"{where} is outside the bounds {np.round(lo, 2).tolist()} to "
                f"{np.round(hi, 2).tolist()}",
            )
        ]
    if abs(start[2] - world.ground_z) > GROUND_TOLERANCE:
        message = (
            f"{where} is not on the ground (z = {world.ground_z:.3f}): a ground robot "
            "starts on it; set the start's z or 'ground: {z: ...}'"
        )
        return [Finding("error", message)]
    if not world.is_free(start[None], radius, "ground")[0]:
        return [
            Finding(
                "error",
                f"{where} is inside an obstacle or within {radius:g} m of one "
                "(ground robot); move 'start:'",
            )
        ]
    return []


def _parts(info: InstanceInfo) -> list[Finding]:
    if not info.parts:
        return [
            Finding(
                "warning",
                f"{info.name} has no parts: it is inspected as a whole "
                "(name its mesh groups with 'parts:')",
            )
        ]
    custom = [part for part in info.parts if part not in KNOWN_PARTS]
    if not custom:
        return []
    return [
        Finding(
            "warning",
            f"{info.name}: parts {', '.join(custom)} are not in the "
            "built-in vocabulary; they will be used as custom features",
        )
    ]


def _facing(world: World, info: InstanceInfo) -> list[Finding]:
    heading = heading_of(world, info.name)
    if heading is None:
        return []
    xy = object_vertices(world, info)[:, :2]
    centred = xy - xy.mean(axis=0)
    *_, axes = np.linalg.svd(centred, full_matrices=False)
    long = axes[0]
    along, across = np.ptp(centred @ long), np.ptp(centred @ axes[1])
    if along < ELONGATION * max(across, 1e-9):
        return []
    off = abs(math.remainder(math.atan2(long[1], long[0]) - heading, math.pi))
    if off <= math.pi / 4:
        return []
    return [
        Finding(
            "warning",
            f"{info.name}: its long axis lies {math.degrees(off):.0f} deg "
            f"across its heading {math.degrees(heading):.0f} deg; is its "
            "'forward:' axis right?",
        )
    ]


def _overlaps(world: World) -> list[Finding]:
    findings = []
    for a, b in combinations(world.instances.values(), 2):
        if a.bbox_max[2] <= b.bbox_min[2] or b.bbox_max[2] <= a.bbox_min[2]:
            continue
        shared = a.footprint.intersection(b.footprint).area
        if shared > OVERLAP_M2:
            findings.append(
                Finding(
                    "error",
                    f"{a.name} and {b.name} overlap ({shared:.1f} m^2 "
                    "of footprint); move one of them",
                )
            )
    return findings
