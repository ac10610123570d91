import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from seminspect.core.threads import rotate_rows


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_rotate_rows_is_bit_identical_to_the_threaded_product(dtype):
    rng = np.random.default_rng(3)
    rows = rng.normal(size=(50_000, 3)).astype(dtype)
    for quaternion in rng.normal(size=(5, 4)):
        rotation = Rotation.from_quat(quaternion).as_matrix().astype(dtype)
        assert np.array_equal(rotate_rows(rows, rotation), rows @ rotation.T)


def test_rotate_rows_into_a_reused_buffer_gives_the_same_numbers():
    rng = np.random.default_rng(4)
    rows = rng.normal(size=(20_000, 3)).astype(np.float32)
    buffer = np.full_like(rows, np.nan)
    for quaternion in rng.normal(size=(3, 4)):
        rotation = Rotation.from_quat(quaternion).as_matrix().astype(np.float32)
        written = rotate_rows(rows, rotation, out=buffer)
        assert written is buffer
        assert np.array_equal(buffer, rows @ rotation.T)


def test_rotate_rows_rotates():
    quarter_turn = Rotation.from_euler("z", 90, degrees=True).as_matrix()
    assert np.allclose(rotate_rows(np.array([[1.0, 0.0, 0.0]]), quarter_turn), [[0, 1, 0]])
