"""Routine priors are checked against the site before use (issue 29): a map of another site,
at another resolution, recorded in another world or cut short is refused in one line naming
the file, never planned on (which gave exit 0 with "0 of 1 tasks" or change that is not)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import save_npz_atomic
from seminspect.mapping.semantic_cloud import read_npz
from seminspect.mapping.voxel import OCCUPIED, VoxelMap, load_map, save_map
from seminspect.missions.routine.prior import load_prior, save_prior
from seminspect.worlds.routine_sites import SitePair, mine_drift_site

RESOLUTION = 0.1


@pytest.fixture(scope="module")
def site() -> SitePair:
    return mine_drift_site("nominal", 1, 12.0)


@pytest.fixture(scope="module")
def drift_map(site: SitePair) -> VoxelMap:
    """The drift's map as a traverse records it (its box, known cells)."""
    return VoxelMap.from_world(site.historical, RESOLUTION)


def rewritten(source: Path, target: Path, **changes: np.ndarray) -> Path:
    """A copy of a map file with some arrays replaced or added."""
    save_npz_atomic(target, **(read_npz(source) | changes))
    return target


def city_map(resolution: float) -> VoxelMap:
    """What a city mission saves as map.npz: its 150 x 100 x 5 m world, some cells occupied."""
    city = VoxelMap.empty((0.0, 0.0, -resolution / 2), (150.0, 100.0, 5.0), resolution)
    city.states[10:40, 10:40, :5] = OCCUPIED
    return city


def test_a_prior_recorded_for_the_site_is_accepted_and_records_the_site(
    tmp_path: Path, site: SitePair, drift_map: VoxelMap
) -> None:
    path = save_prior(tmp_path / "map.npz", drift_map, site.historical)
    loaded = load_prior(path, RESOLUTION, site)
    np.testing.assert_array_equal(loaded.states, drift_map.states)
    arrays = read_npz(path)
    assert str(arrays["site_frame"]) == "mine-drift"
    np.testing.assert_array_equal(arrays["site_bounds"], site.historical.bounds)
    np.testing.assert_array_equal(load_map(path).states, drift_map.states)  # still a voxel map
    old = save_map(tmp_path / "old.npz", drift_map)  # a prior without the site fields
    np.testing.assert_array_equal(load_prior(old, RESOLUTION, site).states, drift_map.states)


def test_a_city_missions_map_is_refused_as_the_drifts_prior(tmp_path: Path, site: SitePair) -> None:
    path = save_map(tmp_path / "city" / "map.npz", city_map(0.3))
    with pytest.raises(InvalidInputError) as caught:
        load_prior(path, RESOLUTION, site)
    message = str(caught.value)
    assert message.startswith(f"{path}: M_H does not fit the site")
    assert "its cells are 0.3 m, the mission maps at 0.1 m" in message
    assert "it covers x 0.0..150.0 y 0.0..100.2" in message
    assert "the site x 0.0..13.0 y 0.0..5.0" in message
    assert "seminspect routine map" in message and "\n" not in message


def test_a_map_of_another_place_at_the_same_resolution_is_refused(
    tmp_path: Path, site: SitePair, drift_map: VoxelMap
) -> None:
    path = save_map(tmp_path / "city.npz", city_map(RESOLUTION))
    with pytest.raises(InvalidInputError, match=r"covers x 0\.0\.\.150\.0"):
        load_prior(path, RESOLUTION, site)
    shifted = VoxelMap(np.add(drift_map.origin, [1000.0, 0.0, 0.0]), RESOLUTION, drift_map.states)
    with pytest.raises(InvalidInputError, match=r"covers x 1000.0..1013.0"):
        load_prior(save_map(tmp_path / "far.npz", shifted), RESOLUTION, site)
    longer = mine_drift_site("nominal", 1, 30.0)  # the same drift, mapped 30 m long
    path = save_prior(
        tmp_path / "long.npz", VoxelMap.covering(longer.historical, 0.1), longer.historical
    )
    with pytest.raises(InvalidInputError, match=r"covers x 0.0..31.0"):
        load_prior(path, RESOLUTION, site)


def test_a_prior_recorded_in_another_world_is_refused(
    tmp_path: Path, site: SitePair, drift_map: VoxelMap
) -> None:
    campus = dataclasses.replace(site.historical, name="campus")
    path = save_prior(tmp_path / "map.npz", drift_map, campus)
    with pytest.raises(
        InvalidInputError, match="mapped in world 'campus', the site is 'mine-drift'"
    ):
        load_prior(path, RESOLUTION, site)


def test_a_prior_whose_states_were_cut_is_refused(
    tmp_path: Path, site: SitePair, drift_map: VoxelMap
) -> None:
    full = save_prior(tmp_path / "map.npz", drift_map, site.historical)
    cut = rewritten(full, tmp_path / "cut.npz", states=drift_map.states[:5])
    with pytest.raises(FileFormatError) as caught:
        load_prior(cut, RESOLUTION, site)
    message = str(caught.value)
    assert message.startswith(f"{cut}: ") and "(5, 50, 46)" in message
    assert "(130, 50, 46)" in message
    # without the recorded fields (an older file) the extent says what is missing
    old = save_map(tmp_path / "old.npz", VoxelMap(drift_map.origin, 0.1, drift_map.states[:5]))
    with pytest.raises(InvalidInputError, match=r"covers x 0.0..0.5 .* the site x 0.0..13.0"):
        load_prior(old, RESOLUTION, site)


@pytest.mark.parametrize(
    ("changes", "expected"),
    [
        ({"site_bounds": np.zeros(3)}, "site_bounds must be a finite"),
        (
            {"site_bounds": np.array([[0.0, 0, 0], [np.nan, 5, 4.5]])},
            "site_bounds must be a finite",
        ),
        ({"site_frame": np.array(7)}, "site_frame must be the name"),
        ({"origin": np.array([np.nan, 0.0, 0.0])}, "origin"),
        ({"resolution": np.array(0.0)}, "resolution must be > 0"),
        ({"resolution": np.array(-0.1)}, "resolution must be > 0"),
        ({"states": np.zeros((130, 50, 46), dtype=np.float32)}, "voxel states must be"),
    ],
)
def test_broken_fields_of_a_prior_file_are_one_line_format_errors(
    tmp_path: Path,
    site: SitePair,
    drift_map: VoxelMap,
    changes: dict[str, np.ndarray],
    expected: str,
) -> None:
    full = save_prior(tmp_path / "map.npz", drift_map, site.historical)
    broken = rewritten(full, tmp_path / "broken.npz", **changes)
    with pytest.raises(FileFormatError, match=expected) as caught:
        load_prior(broken, RESOLUTION, site)
    assert str(caught.value).startswith(f"{broken}: ")


def test_a_foreign_octomap_is_refused_as_the_drifts_prior(tmp_path: Path, site: SitePair) -> None:
    pyoctomap = pytest.importorskip("pyoctomap")
    tree = pyoctomap.OcTree(RESOLUTION)
    for point in ((500.0, 500.0, 1.0), (520.0, 510.0, 3.0)):
        tree.updateNode(np.array(point), True)
    path = tmp_path / "elsewhere.bt"
    assert tree.writeBinary(str(path))
    with pytest.raises(InvalidInputError, match=r"elsewhere.bt: M_H does not fit .* x 500.0"):
        load_prior(path, RESOLUTION, site)


def ascii_ply(path: Path, points: np.ndarray) -> Path:
    header = f"ply\nformat ascii 1.0\nelement vertex {len(points)}\n"
    header += "".join(f"property float {axis}\n" for axis in "xyz") + "end_header\n"
    path.write_text(header + "".join(f"{x} {y} {z}\n" for x, y, z in points))
    return path


def test_a_point_cloud_of_the_site_is_accepted_and_one_elsewhere_refused(
    tmp_path: Path, site: SitePair
) -> None:
    points = np.asarray(site.historical.mesh.vertices)
    accepted = load_prior(ascii_ply(tmp_path / "drift.ply", points), RESOLUTION, site)
    assert accepted.counts()["occupied"] > 0
    elsewhere = ascii_ply(tmp_path / "elsewhere.ply", np.add(points, [0.0, 1000.0, 0.0]))
    with pytest.raises(InvalidInputError, match=r"covers x -1\.0\.\.13\.4 y 998\.8\.\.1006\.3"):
        load_prior(elsewhere, RESOLUTION, site)
