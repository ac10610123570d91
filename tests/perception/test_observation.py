import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.perception.observation import Observation


def test_a_detection_keeps_its_fields_and_normalises_orientation() -> None:
    z = Observation([1, 2, 3], [0, 0, 0, 2], label="hood", score=0.8, mask_area=120, image="a.png")
    np.testing.assert_array_equal(z.position, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(z.orientation, [0, 0, 0, 1])
    assert (z.label, z.score, z.mask_area, z.image) == ("hood", 0.8, 120, "a.png")


@pytest.mark.parametrize(
    "kwargs",
    [
        {"position": [0, 0, float("nan")]},
        {"position": [0, 0]},
        {"position": [0, 0, 0], "score": 1.5},
        {"position": [0, 0, 0], "score": float("nan")},
        {"position": [0, 0, 0], "mask_area": -1},
        {"position": [0, 0, 0], "orientation": [0, 0, 0, 0]},
        {"position": [0, 0, 0], "stamp": float("inf")},
        {"position": [0, 0, 0], "label": 3},
    ],
)
def test_malformed_observations_are_refused(kwargs) -> None:
    with pytest.raises(InvalidInputError):
        Observation(**kwargs)


def test_view_pose_has_no_label_and_full_confidence() -> None:
    z = Observation.view_pose([1, 1, 1], image="p.png", stamp=2.0)
    assert (z.label, z.score, z.image, z.stamp) == ("", 1.0, "p.png", 2.0)
