import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from seminspect.core.errors import InvalidInputError
from seminspect.geometry.raster import cells_touching_triangles


def test_triangle_on_a_cell_face_touches_both_layers() -> None:
    tri = np.array([[[0.1, 0.1, 1.0], [0.9, 0.1, 1.0], [0.1, 0.9, 1.0]]])
    grid = cells_touching_triangles(tri, (0.0, 0.0, 0.0), 1.0, (2, 2, 3))
    assert grid[0, 0, 0] and grid[0, 0, 1]
    assert grid.sum() == 2


def test_far_triangle_touches_nothing_and_diagonal_skips_corners() -> None:
    far = np.array([[[10.0, 10.0, 10.0], [11.0, 10.0, 10.0], [10.0, 11.0, 10.0]]])
    assert not cells_touching_triangles(far, (0, 0, 0), 1.0, (3, 3, 3)).any()
    # A slanted triangle through the middle of a 3x3x1 grid misses the far corner cells,
    # which a bounding-box test would wrongly mark.
    slanted = np.array([[[0.0, 0.0, 0.5], [3.0, 0.0, 0.5], [0.0, 3.0, 0.5]]])
    grid = cells_touching_triangles(slanted, (0, 0, 0), 1.0, (3, 3, 1))
    assert grid[0, 0, 0] and grid[2, 0, 0] and grid[0, 2, 0]
    assert not grid[2, 2, 0]


def test_anisotropic_cells_flatten_a_height_band() -> None:
    wall = np.array([[[2.0, 0.0, 0.0], [2.0, 4.0, 0.0], [2.0, 0.0, 3.0]]])
    grid = cells_touching_triangles(wall, (0.0, 0.0, 0.5), (0.5, 0.5, 1.0), (8, 8, 1))
    assert grid[:, :, 0].any(axis=1).tolist() == [False] * 3 + [True, True] + [False] * 3


@pytest.mark.parametrize(
    ("triangles", "cell"),
    [(np.zeros((1, 3, 2)), 1.0), (np.zeros((1, 3, 3)), 0.0), (np.zeros((1, 3, 3)), -1.0)],
)
def test_bad_input_is_refused(triangles, cell) -> None:
    with pytest.raises(InvalidInputError):
        cells_touching_triangles(triangles, (0, 0, 0), cell, (2, 2, 2))


coordinate = st.floats(0.0, 4.0, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(coordinate, coordinate, coordinate), min_size=3, max_size=3))
def test_every_point_of_a_triangle_lies_in_a_marked_cell(corners) -> None:
    tri = np.array([corners])
    grid = cells_touching_triangles(tri, (0.0, 0.0, 0.0), 0.5, (8, 8, 8))
    weights = np.random.default_rng(0).dirichlet((1, 1, 1), size=200)
    points = weights @ tri[0]
    cells = np.clip(np.floor(points / 0.5).astype(int), 0, 7)
    assert grid[tuple(cells.T)].all()
    # and nothing far from the triangle's box is marked
    marked = np.argwhere(grid) * 0.5
    assert np.all(marked >= tri[0].min(axis=0) - 0.5 - 1e-9)
    assert np.all(marked <= tri[0].max(axis=0) + 1e-9)
