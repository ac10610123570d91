"""The live view of a routine mission: its messages say what the run holds, and in a real
browser the page fills and updates while a mission runs and ends with the run's own counts."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from live_pages import RecordingServer, grew, watch_in_browser
from seminspect.mapping.voxel import VoxelMap
from seminspect.missions.routine.config import RoutineConfig
from seminspect.missions.routine.live import ActiveView, LiveState, LiveWatch
from seminspect.missions.routine.run import RoutineResult, run_routine
from seminspect.report.live_common import MAX_MAP_POINTS
from seminspect.report.live_routine import (
    PENDING,
    TRACKED,
    UNREACHABLE,
    RoutineFeed,
    routine_page,
)
from seminspect.report.live_server import LiveServer

SMALL = {"scenario": "receding", "seed": 1, "length": 12.0}
TRACES = ("M_H", "M_C", "regions", "planned views", "tour", "views flown", "path", "robot")


@pytest.fixture(scope="module")
def feed_messages(tmp_path_factory: pytest.TempPathFactory) -> tuple[RecordingServer, Path]:
    server = RecordingServer()
    out = tmp_path_factory.mktemp("live") / "run"
    feed = RoutineFeed(server)  # type: ignore[arg-type]
    run_routine(RoutineConfig(**SMALL), out, watch=LiveWatch(feed))
    return server, out


def _views(out: Path) -> list[dict]:
    return list(csv.DictReader((out / "views.csv").read_text().splitlines()))


def test_the_scene_is_the_prior_the_regions_and_every_planned_view(feed_messages) -> None:
    server, out = feed_messages
    scene = server.scene
    assert scene is not None
    tour = json.loads((out / "tour.json").read_text())["tasks"]
    assert scene["tasks"] == [t["task"] for t in tour]
    traces = scene["traces"]
    assert len(traces["planned views"]["x"]) == sum(len(t["views"]) for t in tour)
    assert len(traces["planned views"]["text"]) == len(traces["planned views"]["x"])
    # each outline closed, then a gap
    assert len(traces["regions"]["x"]) == sum(len(t["region"]) + 2 for t in tour)
    assert 0 < len(traces["M_H"]["x"]) <= MAX_MAP_POINTS


def test_messages_are_the_run_as_it_stood(feed_messages) -> None:
    server, out = feed_messages
    first, last = server.sent[0], server.sent[-1]
    assert first["t"] < last["t"] and first["final"] is None and first["image"] is None
    assert last["final"] == "run completed: 1 of 1 tasks completed"
    assert last["pose"][:3] == pytest.approx(
        [last["traces"]["path"][axis][-1] for axis in "xyz"], abs=0.01
    )
    views = _views(out)
    tour = last["traces"]["tour"]
    assert len(tour["x"]) == len(views) and tour["color"] == [TRACKED] * len(views)
    assert len(last["traces"]["views flown"]["x"]) == len(views)
    assert last["traces"]["views flown"]["x"][-1] == pytest.approx(float(views[-1]["x"]), abs=0.01)
    assert last["gamma_s"] == pytest.approx(float(views[-1]["gamma_s"]), abs=1e-3)
    metrics = json.loads((out / "metrics.json").read_text())
    assert last["coverage"] == pytest.approx(metrics["roi_coverage_pct"], abs=1e-3)
    assert 0 < len(last["traces"]["M_C"]["x"]) <= MAX_MAP_POINTS
    assert {"navigate", "tour", "done"} <= {m["phase"] for m in server.sent}
    pictures = [m["image"] for m in server.sent if m["image"] is not None]
    assert pictures and all(p.startswith("data:image/jpeg;base64,") for p in pictures)
    status = dict(last["status"])
    assert status["tasks completed"] == "1 / 1" and status["run"].startswith("completed")
    assert status["views"] == f"{len(views)} tracked, 0 unreachable, 0 to go (of {len(views)})"
    assert status["last cycle"].startswith("Γ_s ")


def _state(outcomes: tuple[bool | None, ...], ended: str | None = None) -> LiveState:
    views = np.arange(3 * len(outcomes), dtype=float).reshape(-1, 3)
    task = ActiveView(0, "wall", views, outcomes, True, 12.5, views[:1])
    return LiveState(
        sim_time=3.0,
        phase="tour",
        trajectory=np.array([[0.0, 1.0, 2.0, 3.0, 0.5], [3.0, 1.5, 2.0, 3.0, 0.5]]),
        current_map=VoxelMap((0.0, 0.0, 0.0), 0.5, np.zeros((4, 4, 4), np.uint8)),
        frame=None,
        task=task,
        last_cycle=None,
        gamma_t=0.5,
        tasks_done=0,
        tasks_total=2,
        collisions=0,
        ended=ended,
        reason="stopped by Ctrl-C" if ended else "",
    )


def test_the_tour_shows_each_views_outcome() -> None:
    feed = RoutineFeed(RecordingServer())  # type: ignore[arg-type]
    message = feed.message(_state((True, False, None)))
    assert message["traces"]["tour"]["color"] == [TRACKED, UNREACHABLE, PENDING]
    assert "unreachable" in message["traces"]["tour"]["text"][1]
    status = dict(message["status"])
    assert status["views"] == "1 tracked, 1 unreachable, 1 to go (of 3)"
    assert status["phase"] == "touring wall" and status["task"] == "wall (1 of 2)"
    assert status["ROI coverage"] == "12.5 %" and status["last cycle"] == "-"
    assert message["pose"] == [1.5, 2.0, 3.0, 0.5] and message["final"] is None
    ended = feed.message(_state((True, None, None), ended="interrupted"))
    assert ended["final"] == "run interrupted: stopped by Ctrl-C"
    json.dumps(ended, allow_nan=False)


@pytest.mark.slow
def test_the_live_view_updates_in_a_browser(tmp_path: Path) -> None:
    out = tmp_path / "run"
    results: list[RoutineResult] = []

    def mission(server: LiveServer) -> None:
        feed = RoutineFeed(server)
        results.append(run_routine(RoutineConfig(**SMALL), out, watch=LiveWatch(feed)))

    tour_js = f"() => document.getElementById('live-scene').data[{TRACES.index('tour')}]"
    seen = watch_in_browser(
        routine_page("live test"), mission, "run completed", tmp_path / "live.png",
        {"tour": tour_js + ".marker.color"},
    )  # fmt: skip
    final = seen.final
    assert seen.errors == []
    assert results and results[0].state == "completed"
    assert set(final) == set(TRACES)
    assert final["M_H"] > 100 and final["planned views"] > 0 and final["regions"] > 0
    assert grew(seen.states) and seen.states[-1][1] == final["path"]
    assert final["M_C"] > 0 and final["robot"] == 1
    views = len(_views(out))
    assert final["tour"] == final["views flown"] == views
    assert seen.values["tour"] == [TRACKED] * views
    assert seen.camera is not None and seen.camera.startswith("data:image/jpeg;base64,")
    assert "ROI coverage" in seen.status and "completed" in seen.status
    assert (tmp_path / "live.png").stat().st_size > 20_000
