import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.core.rng import make_rng


def test_same_seed_and_stream_give_the_same_numbers() -> None:
    assert make_rng(3, "camera").random(5).tolist() == make_rng(3, "camera").random(5).tolist()


def test_streams_and_seeds_are_independent() -> None:
    base = make_rng(3, "camera").random(5).tolist()
    assert make_rng(3, "lidar").random(5).tolist() != base
    assert make_rng(4, "camera").random(5).tolist() != base


def test_negative_seed_is_refused() -> None:
    with pytest.raises(InvalidInputError):
        make_rng(-1)
