"""A watched routine mission: the same outputs as an unwatched one, and states that tell the
truth about the run."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from seminspect.mapping.voxel import load_map
from seminspect.missions.routine.config import RoutineConfig
from seminspect.missions.routine.live import LiveScene, LiveState, LiveWatch
from seminspect.missions.routine.run import PRIOR_FILE, run_routine

SMALL = {"scenario": "receding", "seed": 1, "length": 12.0}
#: Columns of views.csv and keys of tour.json that time the planner (wall clock, not the run).
TIMINGS = {"cycle_ms", "sa_s", "reference_s"}


class _EveryStep:
    """A feed that wants every state and keeps what the tests check of each."""

    def __init__(self) -> None:
        self.scene: LiveScene | None = None
        self.states: list[dict] = []

    def start(self, scene: LiveScene) -> None:
        self.scene = scene

    def ready(self) -> bool:
        return True

    def publish(self, state: LiveState) -> None:
        task = state.task
        self.states.append(
            {
                "t": state.sim_time,
                "last_row_t": float(state.trajectory[-1, 0]),
                "rows": len(state.trajectory),
                "phase": state.phase,
                "task": None if task is None else task.name,
                "outcomes": None if task is None else task.outcomes,
                "toured": None if task is None else task.toured,
                "flown": 0 if task is None else len(task.flown),
                "coverage": None if task is None else task.coverage_pct,
                "frame_t": None if state.frame is None else state.frame.stamp,
                "cycle_t": None if state.last_cycle is None else state.last_cycle.t,
                "occupied": state.current_map.counts()["occupied"],
                "done": state.tasks_done,
                "ended": state.ended,
                "reason": state.reason,
            }
        )


@pytest.fixture(scope="module")
def watched(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, _EveryStep]:
    root = tmp_path_factory.mktemp("live")
    config = RoutineConfig(**SMALL)
    run_routine(config, root / "plain")
    feed = _EveryStep()
    run_routine(config, root / "watched", watch=LiveWatch(feed))
    return root / "plain", root / "watched", feed


def _without_timings(path: Path) -> object:
    if path.suffix == ".csv":
        rows = list(csv.DictReader(path.read_text().splitlines()))
        return [{k: v for k, v in row.items() if k not in TIMINGS} for row in rows]
    tasks = json.loads(path.read_text())["tasks"]
    return [{k: v for k, v in task.items() if k not in TIMINGS} for task in tasks]


def test_a_watched_mission_decides_as_an_unwatched_one(watched) -> None:
    plain, seen, _ = watched
    for name in ("trajectory.csv", "events.jsonl", "map.npz", PRIOR_FILE):
        assert (seen / name).read_bytes() == (plain / name).read_bytes(), name
    for name in ("views.csv", "tour.json"):  # byte for byte but for the planner's wall times
        assert _without_timings(seen / name) == _without_timings(plain / name), name
    metrics = [json.loads((run / "metrics.json").read_text()) for run in (plain, seen)]
    for key in ("cycles", "roi_coverage_pct", "gamma_s_max", "collisions", "tasks_completed"):
        assert metrics[0][key] == metrics[1][key], key


def test_the_scene_is_the_prior_and_the_planned_views(watched) -> None:
    plain, _, feed = watched
    scene = feed.scene
    assert scene is not None
    assert np.array_equal(scene.prior.states, load_map(plain / PRIOR_FILE).states)
    tour = json.loads((plain / "tour.json").read_text())["tasks"]
    assert [t.name for t in scene.tasks] == [t["task"] for t in tour]
    assert sum(len(t.views) for t in scene.tasks) == sum(len(t["views"]) for t in tour)


def test_states_follow_the_mission(watched) -> None:
    plain, _, feed = watched
    states = feed.states
    assert len(states) > 10
    times = [s["t"] for s in states]
    assert times == sorted(times)
    assert all(s["last_row_t"] == pytest.approx(s["t"]) for s in states)
    assert {"navigate", "tour"} <= {s["phase"] for s in states}
    # views are counted off one by one during the tour, each frame no later than the state
    toured = [s for s in states if s["toured"]]
    done = [sum(o is not None for o in s["outcomes"]) for s in toured]
    assert done == sorted(done) and done[-1] == len(toured[-1]["outcomes"])
    assert all(s["frame_t"] is None or s["frame_t"] <= s["t"] + 1e-9 for s in states)
    assert all(s["cycle_t"] == s["frame_t"] for s in toured)
    assert np.diff([s["occupied"] for s in states]).min() >= 0  # M_C only grows here
    views = (plain / "views.csv").read_text().splitlines()[1:]
    assert states[-1]["flown"] == len(views)
    assert states[-1]["coverage"] == pytest.approx(
        json.loads((plain / "metrics.json").read_text())["roi_coverage_pct"]
    )


def test_the_last_state_says_how_the_run_ended(watched) -> None:
    _, _, feed = watched
    assert [s["ended"] for s in feed.states[:-1]] == [None] * (len(feed.states) - 1)
    last = feed.states[-1]
    assert (last["ended"], last["reason"], last["phase"]) == (
        "completed", "1 of 1 tasks completed", "done"
    )  # fmt: skip
    assert last["done"] == 1 and all(last["outcomes"])


def test_a_watch_publishes_nothing_before_it_is_attached() -> None:
    feed = _EveryStep()
    watch = LiveWatch(feed)
    watch.publish(ended="failed", reason="no mission")
    watch.step(None)
    assert feed.states == []
    with pytest.raises(RuntimeError, match="before attach"):
        watch.state()
