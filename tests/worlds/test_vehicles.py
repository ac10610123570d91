import math

import numpy as np
import pytest

from seminspect.worlds import VEHICLE_PARTS, WorldBuilder
from seminspect.worlds.vehicles import car_pieces, truck_pieces
from sim_worlds import car_world


@pytest.mark.parametrize(
    ("pieces", "size_range"),
    [
        (car_pieces, [(4.4, 4.7), (1.85, 2.0), (1.45, 1.55)]),
        (truck_pieces, [(7.0, 9.0), (2.4, 2.6), (3.0, 3.5)]),
    ],
)
def test_vehicles_have_every_part_and_their_size(pieces, size_range) -> None:
    solids = pieces()
    labels = {label for piece in solids for label in piece.labels}
    assert set(VEHICLE_PARTS) <= labels
    vertices = np.vstack([p.vertices for p in solids])
    extent = vertices.max(axis=0) - vertices.min(axis=0)
    for value, (low, high) in zip(extent, size_range, strict=True):
        assert low <= value <= high
    assert vertices[:, 2].min() == pytest.approx(0.0, abs=1e-9)


def test_parts_do_not_overlap_so_the_volume_is_exact() -> None:
    builder = WorldBuilder("v")
    builder.add_object(car_pieces(), "car")
    builder.add_ground((-5, -5), (5, 5))
    world = builder.build([(-5, -5, 0), (5, 5, 3)], (-4, -4, 0))
    # The car's volume (sum of its closed, touching parts) is far below its 4.5x1.9x1.5 box.
    volume = world.instances[1].volume
    assert 6.5 < volume < 8.0


def _first_part(world, origin, direction) -> str:
    d = np.asarray(direction, dtype=np.float32)[None] / np.linalg.norm(direction)
    _, face = world.raycaster.cast(np.asarray(origin, float), d)
    return world.part_names[world.face_part[face[0]]] if face[0] >= 0 else "<miss>"


@pytest.mark.parametrize(
    ("origin", "direction", "part"),
    [
        ((1.5, 0.0, 5.0), (0, 0, -1), "hood"),
        ((-1.6, 0.0, 5.0), (0, 0, -1), "trunk"),
        ((6.0, 0.0, 0.5), (-1, 0, 0), "front-bumper"),
        ((-6.0, 0.0, 0.5), (1, 0, 0), "back-bumper"),
        ((0.5, 6.0, 0.6), (0, -1, 0), "front-left-door"),
        ((-0.5, -6.0, 0.6), (0, 1, 0), "back-right-door"),
        ((1.4, 6.0, 0.33), (0, -1, 0), "front-left-wheel"),
        ((-1.4, -6.0, 0.33), (0, 1, 0), "back-right-wheel"),
        ((6.0, 0.7, 0.8), (-1, 0, 0), "front-left-light"),
        ((-6.0, -0.7, 0.8), (1, 0, 0), "back-right-light"),
        ((5.0, 0.0, 2.7), (-1, 0, -0.3), "front-glass"),
        ((-0.2, 0.0, 5.0), (0, 0, -1), "roof"),
    ],
)
def test_a_ray_aimed_at_a_part_returns_that_part(origin, direction, part) -> None:
    assert _first_part(car_world(), origin, direction) == part


def test_labels_turn_with_the_vehicle() -> None:
    world = car_world(yaw=math.pi / 2)  # nose along +y: the left side faces -x
    assert _first_part(world, (-6.0, 0.5, 0.6), (1, 0, 0)) == "front-left-door"
    assert _first_part(world, (0.0, 1.5, 5.0), (0, 0, -1)) == "hood"
