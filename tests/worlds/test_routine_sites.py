import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError, UnknownNameError
from seminspect.worlds import save_world
from seminspect.worlds.routine_sites import (
    ADVANCE_M,
    RECEDING_DEPTH_M,
    SCENARIOS,
    mine_drift_site,
    user_site,
)

LENGTH = 12.0


def face_x(world):
    info = world.instance_named("rock-face-1")
    return float(info.bbox_min[0] + info.bbox_max[0]) / 2


def test_nominal_pair_is_one_world():
    site = mine_drift_site("nominal", 1, LENGTH)
    assert site.historical is site.current
    assert [name for name, _ in site.tasks] == ["face"]


def test_receding_block_exists_only_in_the_historical_world():
    site = mine_drift_site("receding", 1, LENGTH)
    assert len(site.historical.instances_of("rock")) == 1
    assert not site.current.instances_of("rock")
    depth = site.change["depth_m"]
    assert RECEDING_DEPTH_M[0] <= depth <= RECEDING_DEPTH_M[1]
    block = site.historical.instances_of("rock")[0]
    assert block.bbox_min[0] == pytest.approx(LENGTH - depth)
    np.testing.assert_allclose(site.tasks[0][1][:, 0], LENGTH - depth)


def test_advancing_face_moves_towards_the_portal_by_a_seeded_distance():
    shifts = set()
    for seed in range(3):
        site = mine_drift_site("advancing", seed, LENGTH)
        shift = face_x(site.historical) - face_x(site.current)
        assert shift == pytest.approx(site.change["advance_m"], abs=1e-6)
        assert ADVANCE_M[0] <= shift <= ADVANCE_M[1]
        shifts.add(round(shift, 6))
    assert len(shifts) == 3
    again = mine_drift_site("advancing", 2, LENGTH)
    assert again.change == mine_drift_site("advancing", 2, LENGTH).change


def test_rockfall_blocks_the_middle_of_the_drift_but_leaves_a_gap():
    site = mine_drift_site("obstructed", 0, LENGTH)
    assert not site.historical.instances_of("rock")
    x0, x1 = site.change["rockfall_x_m"]
    before, after = [x0 - 1.0, 1.5, 1.5], [x1 + 1.0, 1.5, 1.5]
    assert not site.current.segment_is_free(before, after, 0.3, "aerial")
    assert site.historical.segment_is_free(before, after, 0.3, "aerial")
    assert site.current.segment_is_free([x0 - 1.0, 4.0, 1.5], [x1 + 1.0, 4.0, 1.5], 0.3, "aerial")
    assert [name for name, _ in site.tasks] == ["wall", "face"]


def test_unknown_scenario_suggests_names():
    with pytest.raises(UnknownNameError, match="receding"):
        mine_drift_site("recedng", 0)
    assert SCENARIOS == ("nominal", "receding", "advancing", "obstructed")


def test_user_pair_from_two_saved_worlds(tmp_path):
    site = mine_drift_site("advancing", 0, LENGTH)
    save_world(site.historical, tmp_path / "before")
    save_world(site.current, tmp_path / "after")
    pair = user_site(
        (tmp_path / "before" / "world.ply", tmp_path / "before" / "labels.json"),
        (tmp_path / "after" / "world.ply", tmp_path / "after" / "labels.json"),
    )
    assert pair.tasks == ()
    assert len(pair.current.triangles) == len(site.current.triangles)


def test_bad_drift_options_are_refused():
    from seminspect.worlds.underground import drift_world

    with pytest.raises(InvalidInputError, match="face advance"):
        drift_world(0, 12.0, face_advance=7.0)


def test_world_directories_need_one_mesh_and_one_labels_file(tmp_path):
    from seminspect.worlds.routine_sites import world_files

    with pytest.raises(InvalidInputError, match="not a directory"):
        world_files(tmp_path / "missing")
    (tmp_path / "world.ply").write_text("ply\n")
    with pytest.raises(InvalidInputError, match="labels"):
        world_files(tmp_path)
    (tmp_path / "labels.json").write_text("{}")
    assert [p.name for p in world_files(tmp_path)] == ["world.ply", "labels.json"]
