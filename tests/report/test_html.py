"""report.html: the figures match the graphs, the page is self-contained, and it renders in a
real (headless) browser when one is installed."""

from __future__ import annotations

import os
import shutil
from collections import Counter
from pathlib import Path

import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.graphs.lsg.io import load_graph
from seminspect.graphs.terrain.io import save_terrain_graph
from seminspect.graphs.terrain.prompting import TaskPrompts
from seminspect.graphs.terrain.scene_graph import build_terrain_graph
from seminspect.mapping.formats.pointfiles import PointData
from seminspect.mapping.ingest import cloud_from_point_data
from seminspect.report.html import REPORT_FILE, THUMBNAIL_WIDTH, write_report

CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
]


def _chromium() -> str | None:
    """A Chromium binary: $SEMINSPECT_CHROMIUM, Debian's package, or one on PATH."""
    for candidate in (os.environ.get("SEMINSPECT_CHROMIUM"), "/usr/bin/chromium"):
        if candidate and Path(candidate).is_file():
            return candidate
    return shutil.which("chromium") or shutil.which("chromium-browser")


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

    return {m[0]: int(m[1]) for m in re.findall(r'"meta":\{"layer":"(\w+)","nodes":(\d+)\}', page)}


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


def test_a_directory_without_a_graph_is_refused(tmp_path: Path) -> None:
    with pytest.raises(InvalidInputError, match=r"no graph\.json"):
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


def _open_in_browser(report: Path, screenshot: Path) -> tuple[list[dict], str | None, list[str]]:
    """Layer traces as the page's plotly sees them, the hover panel, every console error."""
    chromium = _chromium()
    if chromium is None:
        pytest.skip("no Chromium found (apt-get install chromium, or set $SEMINSPECT_CHROMIUM)")
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed")
    errors: list[str] = []
    with sync_api.sync_playwright() as driver:
        browser = driver.chromium.launch(executable_path=chromium, args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": 1400, "height": 1000})
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda exc: errors.append(str(exc)))
            page.goto(report.as_uri())
            page.wait_for_function(
                "document.getElementById('figure-scene')?._fullLayout?.scene !== undefined",
                timeout=60_000,
            )
            # gd.data keeps the figure's (binary) input; _fullData has what plotly drew
            traces = page.evaluate(
                "(gd => gd.data.map((t, i) => ({meta: t.meta ?? null, "
                "points: gd._fullData[i]._length})))(document.getElementById('figure-scene'))"
            )
            hover = page.evaluate(_HOVER_FIRST_IMAGE)
            page.screenshot(path=str(screenshot))
        finally:
            browser.close()
    return traces, hover, errors


@pytest.mark.slow
def test_mission_report_renders_in_a_browser(
    mission_report: Path, small_mission_dir: Path, tmp_path: Path
) -> None:
    screenshot = tmp_path / "report.png"
    traces, hover, errors = _open_in_browser(mission_report, screenshot)
    assert errors == []
    assert hover is not None and "score" in hover and 'src="data:image/jpeg;base64,' in hover
    rendered = {layer: t["points"] for layer, t in _by_layer(traces).items()}
    assert rendered == _expected_mission_layers(small_mission_dir)
    assert screenshot.stat().st_size > 20_000


def _by_layer(traces: list[dict]) -> dict[str, dict]:
    return {t["meta"]["layer"]: t for t in traces if t["meta"]}


@pytest.mark.slow
def test_terrain_report_renders_in_a_browser(terrain_report: Path, tmp_path: Path) -> None:
    traces, _, errors = _open_in_browser(terrain_report, tmp_path / "terrain.png")
    assert errors == []
    layers = _by_layer(traces)
    assert set(layers) == {"Points", "Objects", "Places", "Regions", "Map"}
    assert all(t["points"] == t["meta"]["nodes"] for t in layers.values())
