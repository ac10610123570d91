"""Units and the local origin of point files in survey coordinates."""

import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.mapping.local_frame import check_units, choose_units, to_local_frame


def test_feet_and_us_survey_feet_convert_exactly() -> None:
    points = np.array([[10.0, 20.0, 30.0], [11.0, 21.0, 31.0]])
    metres, frame = to_local_frame(points, "ft", "ft", "test")
    np.testing.assert_allclose(metres, points * 0.3048)
    metres, _ = to_local_frame(points, "us-ft", "m", "test")
    np.testing.assert_allclose(metres[:, :2], points[:, :2] * 1200 / 3937)
    np.testing.assert_allclose(metres[:, 2], points[:, 2])
    assert frame.origin_m == (0.0, 0.0, 0.0)


def test_utm_coordinates_move_to_a_recorded_whole_metre_origin() -> None:
    utm = np.array([[512_700.73, 5_403_547.5, 295.2], [512_800.1, 5_403_600.0, 301.0]])
    local, frame = to_local_frame(utm, "m", "m", "test")
    assert frame.origin_m == (512_700.0, 5_403_547.0, 295.0)
    np.testing.assert_allclose(local[0], [0.73, 0.5, 0.2], atol=1e-9)
    back = (local + np.array(frame.origin_m)) / np.array(frame.metres_per_unit)
    np.testing.assert_allclose(back, utm, rtol=0, atol=1e-9)
    assert frame.to_json()["origin_m"] == [512_700.0, 5_403_547.0, 295.0]


def test_a_local_metric_cloud_keeps_its_coordinates_bit_for_bit() -> None:
    points = np.random.default_rng(0).uniform(-50, 50, (100, 3))
    local, frame = to_local_frame(points, "m", "m", "test")
    assert np.array_equal(local, points) and not any(frame.origin_m)


def test_the_option_wins_over_the_header_which_wins_over_metres() -> None:
    assert choose_units("m", "ft", "ft", "GeoTIFF key 3076")[:2] == ("m", "m")
    assert choose_units(None, "ft", None, "WKT")[:2] == ("ft", "ft")
    assert choose_units(None, None, None, "")[:2] == ("m", "m")
    with pytest.raises(InvalidInputError, match="--units must be one of m, ft, us-ft"):
        check_units("yard")
