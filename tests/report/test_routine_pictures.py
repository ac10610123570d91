import pytest

from seminspect.missions.routine.config import RoutineConfig
from seminspect.missions.routine.run import run_routine
from seminspect.report.routine import comparison_figure, load_views, render_routine


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("pictures") / "run"
    run_routine(RoutineConfig(scenario="advancing", seed=0, length=12.0), out)
    return out


def test_pictures_are_drawn_from_the_run_directory(run_dir):
    written = render_routine(run_dir)
    assert {p.name for p in written} == {"performance.png", "changes.png"}
    assert all(p.stat().st_size > 10_000 for p in written)


def test_time_series_reads_back_and_compares(run_dir):
    views = load_views(run_dir)
    assert len(views["t"]) > 0 and (views["t"][1:] >= views["t"][:-1]).all()
    figure = comparison_figure({"a": run_dir, "b": run_dir})
    assert len(figure.axes) == 4


def test_an_empty_run_directory_draws_empty_panels(tmp_path, run_dir):
    (tmp_path / "config.json").write_bytes((run_dir / "config.json").read_bytes())
    written = render_routine(tmp_path)
    assert [p.name for p in written] == ["performance.png"]


def test_a_prior_of_another_format_is_compared_as_the_run_saved_it(tmp_path, run_dir):
    """A .bt (or .ply, .pcd) prior is read as the run saved it beside M_C, so the change
    report is drawn for it too."""
    import json
    import shutil

    copy = tmp_path / "run"
    shutil.copytree(run_dir, copy)
    config = json.loads((copy / "config.json").read_text())
    config["config"]["prior"] = str(tmp_path / "elsewhere" / "site.bt")  # not there: not read
    (copy / "config.json").write_text(json.dumps(config))
    written = render_routine(copy)
    assert {p.name for p in written} == {"performance.png", "changes.png"}
