import math

import numpy as np
import pytest
import trimesh

from seminspect.core.errors import InvalidInputError
from seminspect.worlds.shapes import box, cylinder, pose_matrix, prism_xz, rotated_y_axis


def _mesh(piece) -> trimesh.Trimesh:
    return trimesh.Trimesh(piece.vertices, piece.faces, process=True)


def test_box_is_a_closed_outward_solid_with_labelled_sides() -> None:
    piece = box((0, 0, 0), (2, 3, 4), "body", top="hood", left="door")
    mesh = _mesh(piece)
    assert mesh.is_watertight and mesh.volume == pytest.approx(24.0)
    normals = mesh.face_normals
    for label, direction in (("hood", (0, 0, 1)), ("door", (0, 1, 0))):
        own = np.array(piece.labels) == label
        assert own.sum() == 2 and np.allclose(normals[own], direction)
    assert piece.labels.count("body") == 8


def test_prism_edges_carry_their_labels() -> None:
    piece = prism_xz([(0, 0), (2, 0), (1, 1)], (-1, 1), ["floor", "slope", "glass"], "l", "r")
    mesh = _mesh(piece)
    assert mesh.is_watertight and mesh.volume == pytest.approx(2.0)
    glass = np.array(piece.labels) == "glass"
    assert np.all(mesh.face_normals[glass][:, 0] < 0)  # the edge from (1, 1) back to (0, 0)


def test_mirroring_keeps_faces_outward() -> None:
    mirrored = box((0, 0, 0), (1, 1, 1), "x").transformed(np.diag([-1.0, 1.0, 1.0, 1.0]))
    assert _mesh(mirrored).volume == pytest.approx(1.0)


def test_wheel_axle_runs_along_y() -> None:
    wheel = rotated_y_axis(cylinder(0.3, 0.2, "wheel"))
    extent = wheel.vertices.max(axis=0) - wheel.vertices.min(axis=0)
    assert extent[1] == pytest.approx(0.2) and extent[2] == pytest.approx(0.6, rel=0.02)


def test_pose_matrix_turns_then_moves() -> None:
    matrix = pose_matrix((1, 2, 0), math.pi / 2)
    assert np.allclose(matrix @ [1, 0, 0, 1], [1, 3, 0, 1])


@pytest.mark.parametrize(
    "make",
    [
        lambda: box((0, 0, 0), (1, 0, 1), "x"),
        lambda: box((0, 0, 0), (1, 1, 1), "x", wing="y"),
        lambda: prism_xz([(0, 0), (1, 0)], (0, 1), ["a", "b"], "l", "r"),
    ],
)
def test_bad_shapes_are_refused(make) -> None:
    with pytest.raises(InvalidInputError):
        make()
