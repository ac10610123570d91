import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError, UnknownNameError
from seminspect.core.rng import make_rng
from seminspect.sensors import NoiseModel, noise_preset
from seminspect.sensors.noise import NormalStream, make_noise


def test_presets() -> None:
    ideal, realistic = noise_preset("ideal"), noise_preset("realistic")
    assert ideal.is_ideal and ideal == NoiseModel()
    assert not realistic.is_ideal
    changed = {
        name for name in NoiseModel.model_fields if getattr(ideal, name) != getattr(realistic, name)
    }
    # realistic sets every fault; the precision of the image noise draw is not one
    assert changed == set(NoiseModel.model_fields) - {"image_noise_float32"}
    with pytest.raises(UnknownNameError, match="realistic"):
        noise_preset("realstic")


def test_every_field_is_documented() -> None:
    for name, field in NoiseModel.model_fields.items():
        assert field.description and len(field.description) > 15, name


def test_formulas() -> None:
    noise = make_noise({"depth_noise_m": 0.01, "depth_noise_per_m": 0.01})
    assert noise.depth_sigma(0.0) == pytest.approx(0.01)
    assert noise.depth_sigma(10.0) == pytest.approx(0.11)
    miss = make_noise({"miss_probability": 0.1, "miss_per_metre": 0.02, "miss_area_scale_px": 100})
    assert miss.miss_chance(5.0, 1e9) == pytest.approx(0.2)
    assert miss.miss_chance(5.0, 100.0) == pytest.approx(1 - 0.8 * (1 - 0.36787944))
    assert miss.miss_chance(100.0, 1e9) == 1.0
    assert miss.miss_chance(0.0, 50.0) > miss.miss_chance(0.0, 500.0)


@pytest.mark.parametrize(
    "values",
    [
        {"mask_erosion_px": -1},
        {"miss_probability": 1.5},
        {"depth_noise_m": float("nan")},
        {"typo": 1},
    ],
)
def test_invalid_settings_are_one_line_errors(values) -> None:
    with pytest.raises(InvalidInputError, match="invalid noise setting"):
        make_noise(values)


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_a_normal_stream_gives_the_generators_deviates_in_order(threads, dtype) -> None:
    sizes = [0, 1, 5000, 9000, 16, 30_000, 3]  # across chunk borders, and one past several
    expected = make_rng(9, "camera").standard_normal(sum(sizes), dtype=dtype)
    stream = NormalStream(make_rng(9, "camera"), threads, chunk=4096)
    taken = np.concatenate([stream.standard_normal(n, dtype=dtype) for n in sizes])
    assert taken.dtype == dtype
    np.testing.assert_array_equal(taken, expected)
    with pytest.raises(InvalidInputError, match="deviates"):
        stream.standard_normal(3, dtype=np.float16)
