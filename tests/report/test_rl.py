"""Pictures of learned-inspection episodes and evaluations."""

import math

import numpy as np
import pytest
from matplotlib.collections import PolyCollection
from matplotlib.patches import Wedge

from seminspect.missions.learning.baselines import OrbitController, RandomController
from seminspect.missions.learning.env import EnvConfig
from seminspect.missions.learning.evaluation import evaluate
from seminspect.missions.learning.rooms import BOX, CYLINDER, TARGET_FACES
from seminspect.report.rl import (
    COVERED,
    FAR,
    UNSEEN,
    coverage_figure,
    episode_top_down,
    face_states,
    solid_outline,
    write_episode_pictures,
)

SHORT = EnvConfig(episode_seconds=2.0)


def test_face_states_split_covered_far_and_unseen():
    distances = np.array([1.0, 3.0, 3.5, np.inf])
    np.testing.assert_array_equal(face_states(distances, 3.0), [2, 2, 1, 0])


def test_outlines_are_the_footprints_of_rotated_solids():
    quarter = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # 90 deg about z
    box = solid_outline(BOX, np.array([5.0, 5.0, 1.0]), quarter, np.array([2.0, 1.0, 0.5]))
    np.testing.assert_allclose(np.sort(np.unique(box[:, 0])), [4.0, 6.0], atol=1e-12)
    np.testing.assert_allclose(np.sort(np.unique(box[:, 1])), [3.0, 7.0], atol=1e-12)
    lying = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # axis along y
    cylinder = solid_outline(CYLINDER, np.zeros(3), lying, np.array([0.5, 2.0, 0.0]))
    assert cylinder[:, 0].max() == pytest.approx(0.5)
    assert cylinder[:, 1].max() == pytest.approx(2.0)


@pytest.fixture(scope="module")
def evaluations():
    traces = {}
    orbit = evaluate(OrbitController(), [0, 4], 2, seed=0, config=SHORT, num_envs=2,
                     policy="orbit", traces=traces)  # fmt: skip
    random = evaluate(RandomController(), [0, 4], 2, seed=0, config=SHORT, num_envs=2)
    return {"orbit": orbit, "random": random}, traces


def test_episode_pictures_are_written(evaluations, tmp_path):
    _, traces = evaluations
    written = write_episode_pictures(traces[4], SHORT, tmp_path, prefix="k4", title="orbit")
    assert [p.name for p in written] == ["k4_top.png", "k4_3d.png", "k4_coverage.png"]
    assert all(p.stat().st_size > 10_000 for p in written)
    assert len(traces[4].face_distances) == TARGET_FACES


def test_coverage_against_time_has_a_line_per_controller_and_a_panel_per_count(evaluations):
    results, _ = evaluations
    figure = coverage_figure(results)
    assert [ax.get_title() for ax in figure.axes] == ["0 obstacles", "4 obstacles"]
    for ax, obstacles in zip(figure.axes, (0, 4), strict=True):
        lines = [line for line in ax.get_lines() if not line.get_label().startswith("_")]
        assert [line.get_label() for line in lines] == ["orbit", "random"]
        # the strict curves, not the lenient ones
        np.testing.assert_allclose(lines[0].get_ydata(), results["orbit"].at(obstacles).curve_mean)
        assert lines[0].get_ydata()[-1] == pytest.approx(
            results["orbit"].at(obstacles).strict_coverage_pct
        )
        feasible = [line.get_ydata()[0] for line in ax.get_lines() if line not in lines]
        assert feasible == [95.0, 100.0]  # 004 Fig 5's lines
        assert "feasible" in ax.get_ylabel()
        assert math.isclose(ax.get_ylim()[1], 101.0)


def test_training_curves_pool_the_episodes_of_each_run(tmp_path):
    from seminspect.report.figures import save_figure
    from seminspect.report.rl import _pooled, training_figure

    steps = np.array([100.0, 200.0, 300.0, 400.0])
    episodes = np.array([1.0, 3.0, 0.0, 2.0])
    coverage = np.array([10.0, 50.0, 0.0, 80.0])
    x, y = _pooled(steps, episodes, coverage, window=2)
    assert np.allclose(x, [150.0, 350.0])
    assert np.allclose(y, [(10.0 + 150.0) / 4.0, 80.0])
    log = tmp_path / "progress.csv"
    log.write_text(
        "update,steps,obstacles,episodes,coverage_pct,crash_pct\n"
        "1,100,0,2,20,50\n2,200,0,0,,\n3,300,4,1,60,0\n"
    )
    path = save_figure(training_figure({"run": log}, window=1), tmp_path / "training.png")
    assert path.stat().st_size > 0


@pytest.mark.parametrize("shape", ["box", "t-pipe"])
def test_the_top_down_view_draws_any_shape_by_its_faces_states(shape, tmp_path):
    from matplotlib.colors import to_rgba

    config = EnvConfig(episode_seconds=3.0, target_shapes=(shape,))
    traces = {}
    evaluate(OrbitController(), [4], 1, seed=0, config=config, num_envs=1, policy="orbit",
             traces=traces)  # fmt: skip
    trace, room = traces[4], traces[4].room
    ax = episode_top_down(trace, config.inspect_range).axes[0]
    (triangles,) = [c for c in ax.collections if isinstance(c, PolyCollection)]
    assert len(triangles.get_paths()) == np.sum(room.face_of_triangle >= 0)
    states = face_states(trace.face_distances, config.inspect_range)
    palette = {tuple(to_rgba(c)) for c in np.array([UNSEEN, FAR, COVERED])[np.unique(states)]}
    assert {tuple(c) for c in triangles.get_facecolors()} == palette
    assert 1 <= len([p for p in ax.patches if isinstance(p, Wedge)]) <= 12
    footprints = [p for p in ax.patches if not isinstance(p, Wedge)]
    assert len(footprints) == 1 + room.obstacle_count  # the room's outline, then obstacles only
    written = write_episode_pictures(trace, config, tmp_path, prefix=shape)
    assert all(p.stat().st_size > 10_000 for p in written)
