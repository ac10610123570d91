import pytest

from seminspect.core.errors import InvalidInputError, UnknownNameError
from seminspect.core.params import PRESETS, make_params, preset


def test_presets_carry_tables_1_and_2() -> None:
    simulated, experimental = preset("urban-simulated"), preset("urban-experimental")
    collapsed = preset("collapsed-buildings")
    # 000 Table 1
    for params, fov in ((simulated, 69.4), (experimental, 86.0)):
        assert params.fov_deg == fov
        assert (params.d_max, params.image_width, params.image_height) == (30.0, 640, 480)
        assert (params.d_thresh_I, params.d_check_T, params.d_check_F) == (5.0, 4.0, 1.5)
        assert (params.gamma_thresh, params.horizon_N, params.epsilon) == (0.3, 3, 2.0)
    # 000 Table 2
    assert (collapsed.fov_deg, collapsed.d_check_T, collapsed.d_check_F) == (69.4, 8.0, 1.5)
    assert (collapsed.gamma_thresh, collapsed.horizon_N, collapsed.epsilon) == (0.4, 3, 5.0)
    # eq (6) weights of 000 Sec VII-A
    assert (simulated.utility_S_p, simulated.utility_S_a, simulated.utility_S_n) == (50, 5, 5)


@pytest.mark.parametrize(
    "changes",
    [
        {"d_check_T": -1.0},
        {"fov_deg": 200.0},
        {"horizon_N": 0},
        {"d_max": float("inf")},
        {"bogus": 1},
    ],
)
def test_impossible_parameters_are_refused(changes) -> None:
    with pytest.raises(InvalidInputError, match="invalid inspection parameter"):
        PRESETS["urban-simulated"].with_overrides(**changes)


def test_unknown_preset_suggests_close_names() -> None:
    with pytest.raises(UnknownNameError, match="urban-simulated"):
        preset("urban-simulate")
    assert make_params({"epsilon": 3.0}).epsilon == 3.0
