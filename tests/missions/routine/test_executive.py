"""A small routine mission end to end: the receding face of 002 Fig 10, adaptive and not."""

import numpy as np
import pytest

from seminspect.core.io import read_versioned_json
from seminspect.mapping.voxel import OCCUPIED, VoxelMap, load_map
from seminspect.missions.routine.config import RoutineConfig
from seminspect.missions.routine.executive import _checkpoints, leg_slack
from seminspect.missions.routine.metrics import read_routine_metrics
from seminspect.missions.routine.run import PRIOR_FILE, run_routine
from seminspect.planning.global_views import pose_is_clear

SMALL = {"scenario": "receding", "seed": 1, "length": 12.0}


@pytest.fixture(scope="module")
def adaptive(tmp_path_factory):
    out = tmp_path_factory.mktemp("routine") / "adaptive"
    return run_routine(RoutineConfig(**SMALL), out)


@pytest.fixture(scope="module")
def baseline(tmp_path_factory, adaptive):
    out = tmp_path_factory.mktemp("routine") / "baseline"
    config = RoutineConfig(**SMALL, adapt=False)
    return run_routine(config, out, prior_path=adaptive.run_dir / PRIOR_FILE)


def test_adaptive_run_completes_and_keeps_the_viewing_distance(adaptive):
    m = adaptive.metrics
    assert adaptive.state == "completed"
    assert m.tasks_completed == m.tasks_total == 1
    assert m.collisions == 0
    assert m.gamma_s_max > 0.5 and m.adapted_cycles > 0
    assert m.view_distance_mae_after_deviation_m < 0.3
    assert m.rmse_after_kabsch_m < m.rmse_before_kabsch_m
    assert m.roi_coverage_pct > 50
    assert 0 < m.viewpoint_utility_mean <= 1
    assert read_routine_metrics(adaptive.run_dir) == adaptive.metrics


def test_baseline_tracks_the_outdated_plan_and_sees_less(adaptive, baseline):
    a, b = adaptive.metrics, baseline.metrics
    assert b.adapted_cycles == 0
    assert b.view_distance_mae_m > a.view_distance_mae_m + 0.5
    assert b.roi_coverage_pct < a.roi_coverage_pct
    assert b.viewpoint_utility_mean < a.viewpoint_utility_mean


def test_run_directory_holds_both_maps_the_tour_and_the_time_series(adaptive):
    root = adaptive.run_dir
    prior, current = load_map(root / PRIOR_FILE), load_map(root / "map.npz")
    assert prior.states.shape == current.states.shape
    tour = read_versioned_json(root / "tour.json", "seminspect.routine-tour", [1])["tasks"][0]
    assert len(tour["views"]) == adaptive.metrics.cycles
    assert tour["sa_length_m"] > 0
    lines = (root / "views.csv").read_text().splitlines()
    assert lines[0].startswith("t,task,k,") and len(lines) == adaptive.metrics.cycles + 1
    change = adaptive.metrics.change_report[0]
    assert change.removed_m3 > 0.1  # the block in front of the face is gone


def test_ctrl_c_leaves_a_truthful_run_directory(tmp_path, adaptive):
    def interrupt(label, share):
        if share > 0.3:
            raise KeyboardInterrupt

    config = RoutineConfig(**SMALL)
    result = run_routine(
        config, tmp_path / "cut", prior_path=adaptive.run_dir / PRIOR_FILE, progress=interrupt
    )
    status = read_versioned_json(tmp_path / "cut" / "status.json", "seminspect.run-status", [1])
    assert result.state == status["state"] == "interrupted"
    metrics = read_routine_metrics(tmp_path / "cut")
    assert metrics.tasks_completed == 0 and 0 < metrics.cycles < adaptive.metrics.cycles


def test_nominal_site_never_crosses_the_threshold(adaptive, tmp_path):
    config = RoutineConfig(scenario="nominal", seed=1, length=12.0)
    result = run_routine(config, tmp_path / "nominal")
    assert result.metrics.gamma_s_max < config.gamma_t
    assert result.metrics.adapted_cycles == 0


def test_checkpoints_cut_a_route_every_segment():
    route = np.array([[0.0, 0, 0], [4, 0, 0], [4, 5, 0]])
    points = _checkpoints(route, 3.0)
    np.testing.assert_allclose(points, [[3, 0, 0], [4, 2, 0], [4, 5, 0]])


def test_priors_load_from_maps_and_point_clouds(tmp_path, adaptive):
    from seminspect.core.errors import FileFormatError
    from seminspect.mapping.voxel import OCCUPIED
    from seminspect.missions.routine.prior import load_prior

    again = load_prior(adaptive.run_dir / PRIOR_FILE, 0.1)
    assert again.counts() == load_map(adaptive.run_dir / PRIOR_FILE).counts()
    cloud = tmp_path / "cloud.ply"
    points = [[1.0, 1.0, 1.0], [2.0, 1.0, 1.0], [2.0, 3.0, 0.5]]
    header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    body = "".join(" ".join(map(str, p)) + "\n" for p in points)
    cloud.write_text(header + "property float z\nend_header\n" + body)
    from_cloud = load_prior(cloud, 0.1)
    assert from_cloud.counts()["occupied"] == 3 and from_cloud.counts()["free"] == 0
    assert (from_cloud.state_at(points) == OCCUPIED).all()
    with pytest.raises(FileFormatError, match="prior map"):
        load_prior(tmp_path / "map.obj", 0.1)


def test_an_octomap_prior_loads(shared_data):
    pytest.importorskip("pyoctomap")
    from seminspect.mapping.formats.octomap import load_octomap
    from seminspect.missions.routine.prior import load_prior

    path = shared_data / "octomap" / "geb079.bt"
    assert load_prior(path, 0.16).counts() == load_octomap(path, 0.16).counts()


def test_pins_the_nominal_row_of_the_reproduction_doc(tmp_path):
    """docs/reproduction.md, 002 nominal: Γ_s max 0.23, utility 0.845, coverage 99.2 %."""
    m = run_routine(RoutineConfig(scenario="nominal", seed=0), tmp_path / "nominal").metrics
    assert m.gamma_s_max == pytest.approx(0.23, abs=0.005)
    assert m.viewpoint_utility_mean == pytest.approx(0.845, abs=0.0005)
    assert m.roi_coverage_pct == pytest.approx(99.2, abs=0.05)


def test_a_point_the_planner_calls_clear_passes_the_leg_check_with_its_slack() -> None:
    resolution, radius = 0.1, 0.6
    grid = VoxelMap.empty([0.0, 0.0, 0.0], [3.0, 3.0, 2.0], resolution)
    rng = np.random.default_rng(0)
    occupied = rng.integers(0, grid.shape, size=(6, 3))
    grid.states[tuple(occupied.T)] = OCCUPIED
    obstacles = grid.origin + (occupied + 0.5) * resolution
    points = rng.uniform([0.0, 0.0, 0.0], [3.0, 3.0, 2.0], size=(3000, 3))
    # The planner's rule: a cell is clear when its centre is `radius` from every obstacle's.
    centres = grid.origin + (np.floor((points - grid.origin) / resolution) + 0.5) * resolution
    distances = np.linalg.norm(centres[:, None] - obstacles[None], axis=2).min(axis=1)
    planner_clear = points[distances >= radius]
    assert len(planner_clear) > 500
    slack = leg_slack(resolution)
    assert all(pose_is_clear(grid, point, radius - slack) for point in planner_clear)
    # without the slack the leg check refuses points of cells the planner calls clear
    assert not all(pose_is_clear(grid, point, radius) for point in planner_clear)
