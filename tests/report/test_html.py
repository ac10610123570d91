"""report.html: the figures match the graphs, the page is self-contained, and it renders in a
real (headless) browser when one is installed."""

from __future__ import annotations

import json
import shutil
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.graphs.lsg.io import load_graph
from seminspect.graphs.terrain.io import save_terrain_graph
from seminspect.graphs.terrain.prompting import TaskPrompts
from seminspect.graphs.terrain.scene_graph import build_terrain_graph
from seminspect.mapping.formats.pointfiles import PointData
from seminspect.mapping.ingest import cloud_from_point_data
from seminspect.report.browser import CHROMIUM_HINT, find_chromium, open_page
from seminspect.report.html import REPORT_FILE, THUMBNAIL_WIDTH, run_kind, write_report


def _expected_mission_layers(run_dir: Path) -> dict[str, int]:
    graph = load_graph(run_dir / "graph.json")
    counts = Counter(n.layer.value.capitalize() for n in graph.nodes() if n.id != "robot")
    return {layer: counts.get(layer, 0) for layer in ("Feature", "Pose", "Level", "Target")}


@pytest.fixture(scope="module")
def mission_report(small_mission_dir: Path, tmp_path_factory) -> Path:
    run_dir = tmp_path_factory.mktemp("html") / "run"
    shutil.copytree(small_mission_dir, run_dir)
    return write_report(run_dir)


@pytest.fixture(scope="module")
def terrain_report(labelled_scene, fake_encoder, tmp_path_factory) -> Path:
    points, labels, names = labelled_scene
    cloud = cloud_from_point_data(PointData(points, labels=labels), fake_encoder, names)
    prompts = TaskPrompts.parse("sidewalk,grass,road", "image of a tree,image of a car")
    build = build_terrain_graph(cloud, prompts, fake_encoder)
    out = tmp_path_factory.mktemp("terrain")
    save_terrain_graph(out / "graph.json", build.scene, layer1_file="layer1.npz")
    return write_report(out)


def _figure_layers(page: str) -> dict[str, int]:
    """Layer name -> node count, read from the traces' ``meta`` in the page's figure JSON."""
    import re

    found = re.findall(r'"meta":\{"layer":"([^"]+)","nodes":(\d+)\}', page)
    return {name: int(count) for name, count in found}


def _external_sources(page: str) -> list[str]:
    """``src``/``href`` of every tag (script contents are not parsed as tags)."""
    from html.parser import HTMLParser

    found: list[str] = []

    class Sources(HTMLParser):
        def handle_starttag(self, tag, attrs) -> None:
            found.extend(v or "" for k, v in attrs if k in {"src", "href"})

    Sources().feed(page)
    return found


def test_mission_report_has_every_layer_and_the_graph_images(
    mission_report: Path, small_mission_dir: Path
) -> None:
    page = mission_report.read_text(encoding="utf-8")
    assert mission_report.name == REPORT_FILE
    assert _figure_layers(page) == _expected_mission_layers(small_mission_dir)
    graph = load_graph(small_mission_dir / "graph.json")
    images = {image for n in graph.nodes() if (image := getattr(n, "image", None))}
    assert images, "the small mission should refer to view images"
    assert page.count('"images/') >= len(images)  # thumbnails keyed by the graph's references
    assert page.count("data:image/jpeg;base64,") == len(images)
    # self-contained: plotly.js inline, nothing fetched from a network
    assert _external_sources(page) == []
    assert mission_report.stat().st_size < 4_000_000 + 60_000 * len(images)
    for title in ("000 Table 3", "000 Table 6", "Target selection over time"):
        assert title in page
    metrics = json.loads((small_mission_dir / "metrics.json").read_text())
    for match in metrics["targets"]["matches"]:  # each graph target beside the site's own name
        assert f"<td>{match['target_id']}</td><td>{match['truth']}</td>" in page


def test_thumbnails_are_small(mission_report: Path) -> None:
    import base64
    import re

    import cv2
    import numpy as np

    page = mission_report.read_text(encoding="utf-8")
    first = re.search(r"data:image/jpeg;base64,([A-Za-z0-9+/=]+)", page)
    assert first is not None
    image = cv2.imdecode(np.frombuffer(base64.b64decode(first[1]), np.uint8), cv2.IMREAD_COLOR)
    assert image.shape[1] == THUMBNAIL_WIDTH


def test_terrain_report_has_layers_two_to_five(terrain_report: Path) -> None:
    import json

    page = terrain_report.read_text(encoding="utf-8")
    document = json.loads((terrain_report.parent / "graph.json").read_text())
    counts = Counter(node["layer"] for node in document["nodes"])
    layers = _figure_layers(page)
    expected = {"Objects": counts[2], "Places": counts[3], "Regions": counts[4], "Map": counts[5]}
    assert {k: layers[k] for k in expected} == expected
    assert layers["Points"] > 0 and expected["Objects"] == 5


def test_an_interrupted_run_without_metrics_or_path_still_gets_a_page(
    small_mission_dir: Path, tmp_path: Path
) -> None:
    run_dir = tmp_path / "stopped"
    shutil.copytree(small_mission_dir, run_dir, ignore=shutil.ignore_patterns("*.html"))
    for name in ("metrics.json", "trajectory.csv", "events.jsonl"):
        (run_dir / name).unlink()
    page = write_report(run_dir).read_text(encoding="utf-8")
    assert "wrote no metrics" in page
    assert _figure_layers(page) == _expected_mission_layers(small_mission_dir)


def test_a_directory_that_is_no_run_is_refused_naming_what_was_looked_for(tmp_path: Path) -> None:
    (tmp_path / "notes").mkdir()  # a subdirectory that is no routine run either
    with pytest.raises(InvalidInputError, match=r"no graph\.json") as refused:
        write_report(tmp_path)
    message = str(refused.value)
    assert "\n" not in message and str(tmp_path) in message
    for looked_for in ("metrics.json", "tour.json", "routine map", "evaluation.json"):
        assert looked_for in message
    with pytest.raises(InvalidInputError, match="is not a directory"):
        write_report(tmp_path / "absent")


def test_a_graph_of_another_kind_is_named_with_its_format(tmp_path: Path) -> None:
    (tmp_path / "graph.json").write_text('{"format": "someone.else", "nodes": []}')
    with pytest.raises(FileFormatError, match=r"graph\.json: neither a 3DLSG.*'someone\.else'"):
        write_report(tmp_path)


#: Hover the first node that has an image (as plotly would report it); the panel's HTML.
_HOVER_FIRST_IMAGE = """() => {
  const gd = document.getElementById('figure-scene');
  const index = gd.data.findIndex(t => Array.isArray(t.customdata) && t.customdata[0]);
  if (index < 0) return null;
  const data = gd.data[index];
  gd.emit('plotly_hover', {points: [{data, pointNumber: 0, customdata: data.customdata[0]}]});
  return document.getElementById('hover-panel').innerHTML;
}"""


@dataclass
class Rendered:
    """What a page showed in the browser."""

    #: Layer traces of the figure as the page's plotly sees them (``meta``, points drawn).
    traces: list[dict]
    #: The hover panel after hovering a node with an image (None when not asked for).
    hover: str | None
    #: Every console error.
    errors: list[str]
    #: What ``then(page)`` returned.
    then: Any = None


def _open_in_browser(
    report: Path,
    screenshot: Path,
    figure: str = "scene",
    hover: bool = True,
    then: Callable[[Any], Any] | None = None,
) -> Rendered:
    """The page in headless Chromium (:func:`seminspect.report.browser.open_page`): the traces
    of ``figure-<figure>``, the hover panel (``hover``), then whatever ``then(page)`` finds."""
    if find_chromium() is None:
        pytest.skip(f"no Chromium found ({CHROMIUM_HINT})")
    pytest.importorskip("playwright.sync_api", reason="playwright is not installed")
    with open_page(report.as_uri()) as (page, errors):
        # gd.data keeps the figure's (binary) input; _fullData has what plotly drew
        traces = page.evaluate(
            "id => (gd => gd.data.map((t, i) => ({meta: t.meta ?? null, "
            "points: gd._fullData[i]._length})))(document.getElementById(id))",
            f"figure-{figure}",
        )
        panel = page.evaluate(_HOVER_FIRST_IMAGE) if hover else None
        page.screenshot(path=str(screenshot))
        found = then(page) if then is not None else None
    return Rendered(traces, panel, errors, found)


#: Move the playback slider to t as a reader's drag would (an ``input`` event), wait until the
#: page has redrawn, and read back what the playback figure drew.
_MOVE_SLIDER = """async (t) => {
  const slider = document.getElementById('playback-time');
  slider.value = t;
  slider.dispatchEvent(new Event('input'));
  const clock = document.getElementById('playback-clock');
  while (clock.textContent !== 't = ' + t.toFixed(1) + ' s') {
    await new Promise((done) => requestAnimationFrame(done));
  }
  const gd = document.getElementById('figure-playback');
  const drawn = {};
  gd.data.forEach((trace, i) => { drawn[trace.meta?.playback] = gd._fullData[i]._length; });
  const robot = gd.data.find((trace) => trace.meta?.playback === 'robot');
  const panel = document.getElementById('playback-view');
  return {drawn, robot: [robot.x[0], robot.y[0]], view: panel.querySelector('img')?.alt ?? null,
          caption: panel.textContent};
}"""


def _replay(times: list[float]) -> Callable[[Any], list[dict]]:
    """The slider moved to each time, then Play and Pause pressed: what was drawn at each."""

    def replay(page: Any) -> list[dict]:
        states = [page.evaluate(_MOVE_SLIDER, t) for t in times]
        page.click("#playback-play")
        page.wait_for_function(
            "t => document.getElementById('playback-time').valueAsNumber > t", arg=times[-1]
        )
        page.click("#playback-play")
        states.append({"button": page.text_content("#playback-play")})
        return states

    return replay


@pytest.mark.slow
def test_mission_report_renders_in_a_browser(
    mission_report: Path, small_mission_dir: Path, tmp_path: Path
) -> None:
    from seminspect.report.html_playback import mission_playback
    from seminspect.runs.directory import load_events
    from seminspect.runs.trajectory import load_trajectory

    graph = load_graph(small_mission_dir / "graph.json")
    images = {image for n in graph.nodes() if (image := getattr(n, "image", None))}
    trajectory = load_trajectory(small_mission_dir)
    playback = mission_playback(graph, load_events(small_mission_dir), trajectory, images)
    times = [0.0, round(playback.end_s / 2, 1)]
    screenshot = tmp_path / "report.png"
    rendered = _open_in_browser(mission_report, screenshot, then=_replay(times))
    assert rendered.errors == []
    hover = rendered.hover
    assert hover is not None and "score" in hover and 'src="data:image/jpeg;base64,' in hover
    drawn = {layer: t["points"] for layer, t in _by_layer(rendered.traces).items()}
    assert drawn == _expected_mission_layers(small_mission_dir)
    assert screenshot.stat().st_size > 20_000
    # the playback: at each time the nodes that stood then, the robot where it was, its view
    layer_of = {n.id: n.layer.value.capitalize() for n in graph.nodes() if n.id != "robot"}
    *states, after_play = rendered.then
    for t, state in zip(times, states, strict=True):
        standing = Counter(layer_of[node] for node in playback.nodes_at(t))
        assert {layer: state["drawn"][layer] for layer in drawn} == {
            layer: standing.get(layer, 0) for layer in drawn
        }
        pose = playback.pose_at(t)
        assert pose is not None and state["robot"] == pytest.approx(pose[:2], abs=1e-3)
        assert state["view"] == playback.view_at(t)
    start, middle = states
    assert sum(start["drawn"][layer] for layer in drawn) == 0
    assert "No inspection view yet" in start["caption"]
    assert 0 < middle["drawn"]["Pose"] < drawn["Pose"]
    assert middle["robot"] != start["robot"] and "latest inspection view" in middle["caption"]
    assert after_play == {"button": "Play"}  # paused again


def _by_layer(traces: list[dict]) -> dict[str, dict]:
    return {t["meta"]["layer"]: t for t in traces if t["meta"]}


@pytest.mark.slow
def test_terrain_report_renders_in_a_browser(terrain_report: Path, tmp_path: Path) -> None:
    rendered = _open_in_browser(terrain_report, tmp_path / "terrain.png")
    assert rendered.errors == []
    layers = _by_layer(rendered.traces)
    assert set(layers) == {"Points", "Objects", "Places", "Regions", "Map"}
    assert all(t["points"] == t["meta"]["nodes"] for t in layers.values())


# --- routine runs and rl evaluations -----------------------------------------------------------


@pytest.fixture(scope="module")
def routine_run(tmp_path_factory) -> Path:
    """A short routine run (the advancing face: M_H differs from M_C) with its pictures."""
    from seminspect.missions.routine.config import RoutineConfig
    from seminspect.missions.routine.run import run_routine
    from seminspect.report.routine import render_routine

    out = tmp_path_factory.mktemp("routine") / "run"
    run_routine(RoutineConfig(scenario="advancing", seed=0, length=12.0), out)
    render_routine(out)
    return out


@pytest.fixture(scope="module")
def routine_report(routine_run: Path) -> Path:
    return write_report(routine_run)


@pytest.fixture(scope="module")
def rl_eval_dir(tmp_path_factory) -> Path:
    """An evaluation of the orbit baseline in short episodes, with its coverage picture."""
    from seminspect.missions.learning.baselines import OrbitController
    from seminspect.missions.learning.env import EnvConfig
    from seminspect.missions.learning.evaluation import evaluate
    from seminspect.report.figures import save_figure
    from seminspect.report.rl import coverage_figure

    out = tmp_path_factory.mktemp("rl")
    short = EnvConfig(episode_seconds=2.0)
    result = evaluate(OrbitController(), [0, 4], 2, 0, config=short, num_envs=2, policy="orbit")
    result.to_json(out / "evaluation.json")
    save_figure(coverage_figure({"orbit": result}), out / "coverage.png")
    return out


def _routine_counts(run_dir: Path) -> dict[str, int]:
    """What the plan figure should hold, counted from the run's own files."""
    import csv
    import json

    tasks = json.loads((run_dir / "tour.json").read_text())["tasks"]
    with (run_dir / "views.csv").open() as handle:
        flown = len(list(csv.DictReader(handle)))
    return {
        "Regions": len(tasks),
        "Planned views": sum(len(task["views"]) for task in tasks),
        "Views flown": flown,
    }


def test_routine_report_shows_the_plan_the_views_flown_and_the_tables(
    routine_report: Path, routine_run: Path
) -> None:
    page = routine_report.read_text(encoding="utf-8")
    layers = _figure_layers(page)
    expected = _routine_counts(routine_run)
    assert {k: layers[k] for k in expected} == expected
    assert expected["Views flown"] > 0 and layers["M_H walls"] > 0
    assert layers["added in M_C"] > 0  # the face advanced between M_H and M_C
    for title in ("Figures (002 Sec V)", "Tasks", "Change report", "Algorithm 1 cycles"):
        assert title in page
    assert "<th>state</th><td>completed</td>" in page
    # the two PNGs as embedded thumbnails, each a link to the picture beside the page
    assert page.count("data:image/jpeg;base64,") == 2
    links = {s for s in _external_sources(page) if not s.startswith("data:image/jpeg;base64,")}
    assert links == {"changes.png", "performance.png"}  # no network, only files beside it
    assert all((routine_run / link).is_file() for link in links)


def test_a_routine_run_stopped_before_its_metrics_still_gets_a_page(
    routine_run: Path, tmp_path: Path
) -> None:
    run_dir = tmp_path / "stopped"
    shutil.copytree(routine_run, run_dir, ignore=shutil.ignore_patterns("*.html"))
    (run_dir / "metrics.json").unlink()  # the tour file still says it is a routine run
    page = write_report(run_dir).read_text(encoding="utf-8")
    assert "wrote no metrics" in page
    assert _figure_layers(page)["Planned views"] == _routine_counts(routine_run)["Planned views"]


def test_a_compare_directory_gets_an_index_and_each_run_its_page(
    routine_run: Path, tmp_path: Path
) -> None:
    for name in ("adaptive", "baseline"):
        shutil.copytree(routine_run, tmp_path / name, ignore=shutil.ignore_patterns("*.html"))
    assert run_kind(tmp_path) == "routine-compare"
    page = write_report(tmp_path).read_text(encoding="utf-8")
    for name in ("adaptive", "baseline"):
        assert (tmp_path / name / REPORT_FILE).is_file()
        assert f'href="{name}/{REPORT_FILE}"' in page
    assert "adaptive vs baseline" in page and "viewing-distance MAE" in page


def test_a_recorded_historical_map_gets_its_page(tmp_path: Path) -> None:
    from seminspect.missions.routine.config import RoutineConfig
    from seminspect.missions.routine.run import map_site

    map_site(RoutineConfig(scenario="advancing", seed=0, length=12.0), tmp_path / "map", None)
    assert run_kind(tmp_path / "map") == "routine-map"
    page = write_report(tmp_path / "map").read_text(encoding="utf-8")
    assert _figure_layers(page)["M_H walls"] > 0 and "occupied cells" in page


def test_rl_report_has_a_curve_per_obstacle_count_and_every_episode(rl_eval_dir: Path) -> None:
    from seminspect.missions.learning.evaluation import EvaluationResult

    result = EvaluationResult.from_json(rl_eval_dir / "evaluation.json")
    assert run_kind(rl_eval_dir) == "rl-eval"
    page = write_report(rl_eval_dir).read_text(encoding="utf-8")
    layers = _figure_layers(page)
    for row in result.results:
        assert layers[f"{row.obstacles} obstacles"] == len(row.curve_times)
    episodes = sum(row.episodes for row in result.results)
    assert layers["timeout (no crash)"] + layers["crashed"] == episodes
    assert "004 Table I" in page and "92.1" in page and "82.6" in page  # the paper beside ours
    row = result.at(4)
    low, high = row.crash_ci
    assert f"{row.crash_pct:.1f} [{low:.1f}-{high:.1f}]" in page  # Wilson interval
    assert "strict coverage" in page and "(a baseline)" in page  # no checkpoint digest
    assert page.count("data:image/jpeg;base64,") == 1  # coverage.png; no episode pictures here


def test_run_kinds_are_told_apart_by_their_files(
    mission_report: Path, terrain_report: Path, routine_run: Path
) -> None:
    assert run_kind(mission_report.parent) == "mission"
    assert run_kind(terrain_report.parent) == "terrain"
    assert run_kind(routine_run) == "routine"


@pytest.mark.slow
def test_routine_report_renders_in_a_browser(
    routine_report: Path, routine_run: Path, tmp_path: Path
) -> None:
    rendered = _open_in_browser(routine_report, tmp_path / "routine.png", hover=False)
    assert rendered.errors == []
    layers = _by_layer(rendered.traces)
    expected = _routine_counts(routine_run)
    assert {k: layers[k]["points"] for k in expected} == expected


@pytest.mark.slow
def test_rl_report_renders_in_a_browser(rl_eval_dir: Path, tmp_path: Path) -> None:
    report = write_report(rl_eval_dir)
    rendered = _open_in_browser(report, tmp_path / "rl.png", "coverage", hover=False)
    assert rendered.errors == []
    layers = _by_layer(rendered.traces)
    assert set(layers) == {"0 obstacles", "4 obstacles"}
    assert all(t["points"] == t["meta"]["nodes"] for t in layers.values())
