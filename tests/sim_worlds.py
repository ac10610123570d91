"""Tiny hand-built worlds with known geometry, shared by the world, sensor, robot and map tests."""

from __future__ import annotations

import math

from seminspect.worlds import World, WorldBuilder
from seminspect.worlds.shapes import box, pose_matrix
from seminspect.worlds.vehicles import vehicle_pieces


def box_world(
    lower=(4.0, -1.0, 0.0),
    upper=(6.0, 1.0, 2.0),
    size=(20.0, 10.0, 5.0),
    floating=None,
) -> World:
    """Ground over [-size/2, size/2] in x/y, one box obstacle, optionally a floating box."""
    builder = WorldBuilder("box")
    half = (size[0] / 2, size[1] / 2)
    builder.add_ground((-half[0], -half[1]), half)
    builder.add_object([box(lower, upper, "side", top="lid")], "crate")
    if floating is not None:
        builder.add_object([box(*floating, "side")], "sign")
    return builder.build(
        bounds=[(-half[0], -half[1], 0.0), (half[0], half[1], size[2])],
        start_position=(-half[0] + 1.0, 0.0, 0.0),
        metadata={"ground_z": 0.0},
    )


def car_world(yaw: float = 0.0, centre=(0.0, 0.0)) -> World:
    """One car on a 30 m x 30 m ground, turned by ``yaw``."""
    builder = WorldBuilder("car")
    builder.add_ground((-15.0, -15.0), (15.0, 15.0))
    builder.add_object(vehicle_pieces("car"), "car", pose_matrix((*centre, 0.0), yaw))
    return builder.build(
        bounds=[(-15.0, -15.0, 0.0), (15.0, 15.0, 5.0)],
        start_position=(-10.0, 0.0, 0.0),
        metadata={"ground_z": 0.0},
    )


def heading(frm, to) -> float:
    """Yaw that looks from ``frm`` to ``to`` in the horizontal plane."""
    return math.atan2(to[1] - frm[1], to[0] - frm[0])
