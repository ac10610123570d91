"""Cars and trucks made of named parts.

Each vehicle is assembled from closed, non-overlapping solids in its own frame: x forward, y to
its left, z up, origin at the centre of its footprint on the ground. Wheels sit in wheel arches
cut out of the lower body, so the parts never overlap and the vehicle's volume is exact. The part
names follow the car-parts vocabulary the segmentation model of 000 Sec VI-B was trained on.
"""

from __future__ import annotations

import numpy as np

from seminspect.worlds.shapes import Piece, box, cylinder, pose_matrix, prism_xz, rotated_y_axis

#: Nominal sizes (length, width, height) in metres.
CAR_SIZE = (4.5, 1.9, 1.5)
TRUCK_SIZE = (8.0, 2.5, 3.2)


def _wheels(x_front: float, x_back: float, y: float, radius: float, width: float) -> list[Piece]:
    wheel = rotated_y_axis(cylinder(radius, width, "wheel"))
    pieces = []
    for x, end in ((x_front, "front"), (x_back, "back")):
        for sign, side in ((1.0, "left"), (-1.0, "right")):
            placed = wheel.transformed(pose_matrix((x, sign * y, radius)))
            pieces.append(placed.relabelled(f"{end}-{side}-wheel"))
    return pieces


def _lights(
    x_face: float, depth: float, y: tuple[float, float], z: tuple[float, float], end: str
) -> list[Piece]:
    """A pair of lights on the face at ``x_face``, spanning ``y`` (inner, outer) on each side."""
    y_in, y_out = y
    x0, x1 = (x_face, x_face + depth) if end == "front" else (x_face - depth, x_face)
    return [
        box((x0, y_in, z[0]), (x1, y_out, z[1]), f"{end}-left-light"),
        box((x0, -y_out, z[0]), (x1, -y_in, z[1]), f"{end}-right-light"),
    ]


def _arched_section(
    x: tuple[float, float],
    half_width: float,
    arch_width: float,
    z: tuple[float, float, float],
    top: str,
) -> list[Piece]:
    """A body section over a wheel: full width above the wheel, narrow between the wheels."""
    z_bottom, z_arch, z_top = z
    return [
        box((x[0], -half_width, z_arch), (x[1], half_width, z_top), "body", top=top),
        box((x[0], -arch_width, z_bottom), (x[1], arch_width, z_arch), "body"),
    ]


def car_pieces() -> list[Piece]:
    """A 4.5 m x 1.9 m x 1.5 m saloon with every part of :data:`VEHICLE_PARTS`."""
    w = 0.95  # half width
    z0, z_arch, z_belt, z_roof = 0.3, 0.66, 0.95, 1.5
    pieces = [
        box((-2.25, -w, z0), (-2.05, w, 0.7), "back-bumper"),
        box((-2.05, -w, z0), (-1.75, w, z_belt), "body", top="trunk"),
        *_arched_section((-1.75, -1.05), w, 0.74, (z0, z_arch, z_belt), top="trunk"),
        box(
            (-1.05, -w, z0),
            (0.0, w, z_belt),
            "body",
            left="back-left-door",
            right="back-right-door",
        ),
        box(
            (0.0, -w, z0),
            (1.05, w, z_belt),
            "body",
            left="front-left-door",
            right="front-right-door",
        ),
        *_arched_section((1.05, 1.75), w, 0.74, (z0, z_arch, z_belt), top="hood"),
        box((1.75, -w, z0), (2.05, w, z_belt), "body", top="hood"),
        box((2.05, -w, z0), (2.25, w, 0.7), "front-bumper"),
        # Cabin halves: the slopes are the windscreens, the sides belong to the doors.
        prism_xz(
            [(0.0, z_belt), (1.05, z_belt), (0.45, z_roof), (0.0, z_roof)],
            (-0.8, 0.8),
            ["body", "front-glass", "roof", "body"],
            left="front-left-door",
            right="front-right-door",
        ),
        prism_xz(
            [(-1.05, z_belt), (0.0, z_belt), (0.0, z_roof), (-0.75, z_roof)],
            (-0.8, 0.8),
            ["body", "body", "roof", "back-glass"],
            left="back-left-door",
            right="back-right-door",
        ),
        *_lights(2.05, 0.06, (0.55, 0.88), (0.72, 0.88), "front"),
        *_lights(-2.05, 0.06, (0.55, 0.88), (0.72, 0.88), "back"),
        *_wheels(1.4, -1.4, 0.85, 0.32, 0.2),
    ]
    return pieces


def truck_pieces() -> list[Piece]:
    """An 8 m x 2.5 m x 3.2 m box truck: cab with hood, cargo box (the trunk) with rear doors."""
    w, narrow = 1.25, 0.93
    z0, z_deck, z_cargo, z_cab = 0.55, 1.02, 2.7, 3.2
    pieces = [
        box((-4.0, -1.2, z0), (-3.8, 1.2, z_deck), "back-bumper"),
        box((-3.8, -narrow, z0), (3.8, narrow, z_deck), "body"),
        # Cargo box in two halves so that each half of its rear face is one door.
        box((-3.8, 0.0, z_deck), (1.2, w, z_cargo), "trunk", back="back-left-door"),
        box((-3.8, -w, z_deck), (1.2, 0.0, z_cargo), "trunk", back="back-right-door"),
        prism_xz(
            [(1.2, z_deck), (2.9, z_deck), (2.9, 2.1), (2.6, z_cab), (1.2, z_cab)],
            (-w, w),
            ["body", "body", "front-glass", "roof", "back-glass"],
            left="front-left-door",
            right="front-right-door",
        ),
        box((2.9, -1.2, z_deck), (3.8, 1.2, 2.0), "body", top="hood"),
        box((3.8, -1.2, z0), (4.0, 1.2, 1.3), "front-bumper"),
        *_lights(3.8, 0.05, (0.7, 1.1), (1.4, 1.65), "front"),
        *_lights(-3.8, 0.05, (0.85, 1.15), (1.1, 1.35), "back"),
        *_wheels(2.6, -2.4, 1.1, 0.5, 0.3),
    ]
    return pieces


def vehicle_pieces(class_name: str, scale: np.ndarray | None = None) -> list[Piece]:
    """The pieces of a ``car`` or ``truck``, optionally stretched by ``(sx, sy, sz)``."""
    pieces = car_pieces() if class_name == "car" else truck_pieces()
    if scale is None:
        return pieces
    matrix = pose_matrix(scale=scale)
    return [p.transformed(matrix) for p in pieces]


def vehicle_size(class_name: str) -> tuple[float, float, float]:
    """Nominal length, width and height of a vehicle class."""
    return CAR_SIZE if class_name == "car" else TRUCK_SIZE
