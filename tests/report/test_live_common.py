"""What the routine and episode live views share: the page's parts and the JSON helpers."""

from __future__ import annotations

import base64
import json

import cv2
import numpy as np

from seminspect.report.live_common import (
    MAX_TRAIL_POINTS,
    PICTURE_WIDTH,
    box_edges,
    jpeg_uri,
    polylines,
    scatter,
    stream_page,
    trail,
    xyz,
)


def test_points_are_lists_to_the_centimetre() -> None:
    assert xyz(np.array([[1.234, 2.0, -0.006], [0.0, 1.0, 2.0]])) == {
        "x": [1.23, 0.0], "y": [2.0, 1.0], "z": [-0.01, 2.0]
    }  # fmt: skip
    assert xyz(np.empty((0, 3))) == {"x": [], "y": [], "z": []}


def test_a_long_path_is_thinned_but_ends_where_the_robot_is() -> None:
    path = np.column_stack([np.arange(5001.0), np.zeros(5001), np.zeros(5001)])
    thinned = trail(path)
    assert len(thinned) <= MAX_TRAIL_POINTS and thinned[-1, 0] == 5000.0
    assert np.array_equal(trail(path[:10]), path[:10])


def test_polylines_and_a_box_are_one_trace_with_gaps() -> None:
    lines = polylines([np.zeros((3, 3)), np.ones((2, 3))])
    assert lines["x"] == [0.0, 0.0, 0.0, None, 1.0, 1.0, None]
    edges = box_edges((0, 0, 0), (2.0, 3.0, 4.0))
    points = {(x, y, z) for x, y, z in zip(*edges.values(), strict=True) if x is not None}
    assert points == {(x, y, z) for x in (0.0, 2.0) for y in (0.0, 3.0) for z in (0.0, 4.0)}
    assert edges["x"].count(None) == 6  # two rings and four posts


def test_a_picture_is_a_jpeg_of_the_pages_width() -> None:
    picture = np.zeros((54, 96, 3), np.uint8)
    picture[10:20, 30:40] = 255
    uri = jpeg_uri(picture)
    assert uri.startswith("data:image/jpeg;base64,")
    data = np.frombuffer(base64.b64decode(uri.split(",", 1)[1]), np.uint8)
    decoded = cv2.imdecode(data, cv2.IMREAD_COLOR)
    assert decoded.shape == (270, PICTURE_WIDTH, 3) and decoded[75, 175].min() > 200


def test_the_page_names_its_traces_and_loads_plotly_from_its_server() -> None:
    page = stream_page("a <title>", "heading", [scatter("path"), scatter("robot")], "a picture")
    assert "<title>a &lt;title&gt;</title>" in page
    assert f"const TRACES = {json.dumps(['path', 'robot'])};" in page
    assert 'src="/plotly.min.js"' in page and "cdn" not in page.lower()
    assert "new EventSource('/events')" in page
