"""``run_routine`` refuses a prior or a region that does not fit the site before its run
(issue 29: a city map as the drift's prior, a cut prior, a region 1000 m away all ran to
exit 0 with wrong change figures or "0 of 1 tasks")."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import save_npz_atomic
from seminspect.mapping.semantic_cloud import read_npz
from seminspect.mapping.voxel import OCCUPIED, VoxelMap, save_map
from seminspect.missions.routine.config import RoutineConfig
from seminspect.missions.routine.run import map_site, run_routine
from seminspect.worlds.routine_sites import face_region

SMALL = {"scenario": "nominal", "seed": 1, "length": 12.0}


def refused_before_the_run(run_dir: Path) -> None:
    assert not run_dir.exists()  # no run directory, so no figures of a mission that did not fit


def test_a_city_map_is_refused_as_the_drifts_prior(tmp_path: Path) -> None:
    city = VoxelMap.empty((0.0, 0.0, -0.15), (150.0, 100.0, 5.0), 0.3)
    city.states[10:40, 10:40, :5] = OCCUPIED
    prior = save_map(tmp_path / "city" / "map.npz", city)
    with pytest.raises(InvalidInputError, match=re.escape(f"{prior}: M_H does not fit the site")):
        run_routine(RoutineConfig(**SMALL), tmp_path / "run", prior_path=prior)
    refused_before_the_run(tmp_path / "run")


def test_a_recorded_prior_whose_states_were_cut_is_refused(tmp_path: Path) -> None:
    recorded = map_site(RoutineConfig(**SMALL), tmp_path / "prior", None)
    arrays = read_npz(recorded)
    assert str(arrays["site_frame"]) == "mine-drift"  # routine map records the site
    cut = save_npz_atomic(tmp_path / "cut.npz", **(arrays | {"states": arrays["states"][:5]}))
    with pytest.raises(FileFormatError, match=r"shape \(5, 50, 46\).* need \(130, 50, 46\)"):
        run_routine(RoutineConfig(**SMALL), tmp_path / "run", prior_path=cut)
    refused_before_the_run(tmp_path / "run")


def test_a_foreign_octomap_is_refused(tmp_path: Path) -> None:
    pyoctomap = pytest.importorskip("pyoctomap")
    tree = pyoctomap.OcTree(0.1)
    tree.updateNode(np.array([500.0, 500.0, 1.0]), True)
    path = tmp_path / "elsewhere.bt"
    assert tree.writeBinary(str(path))
    with pytest.raises(
        InvalidInputError, match=re.escape("elsewhere.bt: M_H does not fit the site")
    ):
        run_routine(RoutineConfig(**SMALL), tmp_path / "run", prior_path=path)
    refused_before_the_run(tmp_path / "run")


def test_a_region_1000_m_away_is_refused_before_the_run(tmp_path: Path) -> None:
    tasks = tmp_path / "tasks.yaml"
    far = np.add(face_region(12.0), [1000.0, 0.0, 0.0]).tolist()
    tasks.write_text(f"regions:\n  - name: face\n    vertices: {far}\n")
    with pytest.raises(FileFormatError, match=re.escape("region 'face' spans x 1012.0..1012.0")):
        run_routine(RoutineConfig(**SMALL), tmp_path / "run", tasks_path=tasks)
    refused_before_the_run(tmp_path / "run")
