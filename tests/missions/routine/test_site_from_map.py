"""Routine sites built from a map's own voxels: the world, the start, refusals, a run."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from seminspect.core.errors import InvalidInputError
from seminspect.missions.routine import RoutineConfig, run_routine
from seminspect.missions.routine.site_from_map import site_from_map
from seminspect.missions.routine.tasks import default_tasks, load_tasks
from seminspect.worlds.voxels import world_from_voxels

RES = 0.2
CONFIG = RoutineConfig(world="map", scenario="map")


def write_room_bt(path: Path, size=(30, 20, 15), free_inside: bool = True) -> Path:
    """A closed room of ``size`` cells of 0.2 m (6 x 4 x 3 m by default) as an OctoMap: the
    shell occupied, the inside free (or occupied too)."""
    pyoctomap = pytest.importorskip("pyoctomap")
    tree = pyoctomap.OcTree(RES)
    for cell in np.ndindex(*size):
        shell = any(c in (0, n - 1) for c, n in zip(cell, size, strict=True))
        tree.updateNode((np.array(cell) + 0.5) * RES, bool(shell or not free_inside))
    assert tree.writeBinary(str(path))
    return path


def east_wall_tasks(path: Path) -> Path:
    """One region on the inside of the room's east wall (x = 5.8 m)."""
    region = [[5.8, 1.2, 0.8], [5.8, 2.8, 0.8], [5.8, 2.8, 2.0], [5.8, 1.2, 2.0]]
    path.write_text(yaml.safe_dump({"regions": [{"name": "east", "vertices": region}]}))
    return path


def test_a_slab_of_voxels_becomes_a_surface_on_its_cell_faces() -> None:
    occupied = np.zeros((10, 6, 6), dtype=bool)
    occupied[2:5, 1:5, 1:5] = True
    world = world_from_voxels(
        occupied, [1.0, 0.0, 0.0], 0.5, name="slab", start_position=[4.0, 1.5, 0.0]
    )
    low, high = world.mesh.bounds
    assert low[0] == pytest.approx(2.0) and high[0] == pytest.approx(3.5)  # cells 2..4 at 0.5 m
    assert world.mesh.is_watertight
    assert np.allclose(world.bounds, [[1.0, 0.0, 0.0], [6.0, 3.0, 3.0]])
    assert not world.instances  # geometry only: nothing to detect


def test_the_site_of_a_room_starts_inside_it_clear_of_the_walls(tmp_path: Path) -> None:
    site = site_from_map(write_room_bt(tmp_path / "room.bt"), CONFIG)
    assert site.historical is site.current
    start = site.historical.start_position
    assert np.allclose(start[:2], [3.0, 2.0], atol=0.3)  # the room's middle
    lifted = start + np.array([0.0, 0.0, 1.5])
    assert site.historical.is_free(lifted[None], CONFIG.robot_radius)[0]
    with pytest.raises(InvalidInputError, match=r"no default tasks; pass a task file \(--tasks"):
        default_tasks(site)


def test_a_map_without_free_space_cannot_be_a_site(tmp_path: Path) -> None:
    solid = write_room_bt(tmp_path / "solid.bt", size=(12, 12, 12), free_inside=False)
    with pytest.raises(InvalidInputError, match=r"solid.bt: no known-free space"):
        site_from_map(solid, CONFIG)


def test_a_map_with_too_little_free_space_is_refused(tmp_path: Path) -> None:
    closet = write_room_bt(tmp_path / "closet.bt", size=(10, 10, 22))  # 1.6 x 1.6 m inside
    with pytest.raises(InvalidInputError, match=r"closet.bt: its largest free space is"):
        site_from_map(closet, CONFIG)


def test_a_routine_run_in_a_map_built_room_completes_without_collisions(tmp_path: Path) -> None:
    bt = write_room_bt(tmp_path / "room.bt")
    site = site_from_map(bt, CONFIG)
    tasks = east_wall_tasks(tmp_path / "tasks.yaml")
    assert load_tasks(tasks, site)
    result = run_routine(CONFIG, tmp_path / "run", prior_path=bt, tasks_path=tasks, site=site)
    assert result.state == "completed", result.reason
    metrics = result.metrics
    assert metrics is not None
    assert (metrics.tasks_completed, metrics.collisions) == (1, 0)
    assert (tmp_path / "run" / "prior" / "map.npz").exists()  # M_H as painted, for changes.png
    change = metrics.change_report[0]
    assert change.added_m3 + change.removed_m3 < 0.1 * change.compared_m3  # one world: no change
    assert "the site of" in (tmp_path / "run" / "summary.md").read_text()


def test_the_freiburg_map_is_a_site_that_starts_in_its_corridor(shared_data) -> None:
    pytest.importorskip("pyoctomap")
    site = site_from_map(shared_data / "octomap" / "geb079.bt", CONFIG)
    start = site.historical.start_position + np.array([0.0, 0.0, 1.5])
    assert -1.3 < start[1] < 1.2 and -6.5 < start[0] < 28.0  # the corridor's floor plan
    assert site.historical.is_free(start[None], CONFIG.robot_radius)[0]
    assert len(site.historical.mesh.faces) > 100_000  # a surface of the office, not a box
