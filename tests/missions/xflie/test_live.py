"""A watched mission: the same outputs as an unwatched one, and states that tell the truth."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from seminspect.missions.xflie.config import make_config
from seminspect.missions.xflie.live import LiveState, LiveWatch
from seminspect.missions.xflie.run import run_mission
from seminspect.worlds import World

CONFIG = {"world": "campus", "scenario": "small", "seed": 0, "time_budget_s": 150.0}


class _EveryFrame:
    """A feed that wants every frame and keeps what the tests check of each state."""

    def __init__(self) -> None:
        self.world: World | None = None
        self.states: list[dict] = []

    def start(self, world: World) -> None:
        self.world = world

    def ready(self) -> bool:
        return True

    def publish(self, state: LiveState) -> None:
        frame = state.frame
        self.states.append(
            {
                "t": state.sim_time,
                "rows": len(state.trajectory),
                "last_row_t": float(state.trajectory[-1, 0]),
                "frame_stamp": None if frame is None else frame.stamp,
                "shape_ok": all(d.mask.shape == frame.shape for d in state.detections)
                if frame is not None
                else not state.detections,
                "targets": len(state.graph.targets()),
                "detected": state.detected,
                "inspected": state.inspected,
                "phase": state.phase,
                "ended": state.ended,
                "next": None if state.next_target is None else state.next_target.target_id,
            }
        )


@pytest.fixture(scope="module")
def watched(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, _EveryFrame]:
    root = tmp_path_factory.mktemp("live")
    config = make_config(CONFIG)
    run_mission(config, root / "plain")
    feed = _EveryFrame()
    run_mission(config, root / "watched", watch=LiveWatch(feed))
    return root / "plain", root / "watched", feed


def test_a_watched_mission_decides_as_an_unwatched_one(watched) -> None:
    plain, seen, _ = watched
    for name in ("graph.json", "trajectory.csv", "events.jsonl"):
        assert (seen / name).read_bytes() == (plain / name).read_bytes(), name


def test_states_follow_the_mission(watched) -> None:
    _, _, feed = watched
    states = feed.states
    assert feed.world is not None and feed.world.name.startswith("campus")
    assert len(states) > 50
    times = [s["t"] for s in states]
    assert times == sorted(times) and times[-1] <= CONFIG["time_budget_s"]
    assert all(s["last_row_t"] == pytest.approx(s["t"]) for s in states)
    # the frame shown is one frame behind the mission, never ahead of it
    assert all(s["frame_stamp"] is None or s["frame_stamp"] <= s["t"] + 1e-9 for s in states)
    assert all(s["shape_ok"] and s["detected"] == s["targets"] for s in states)
    assert {"explore-360", "navigate", "inspect"} <= {s["phase"] for s in states}
    assert np.diff([s["inspected"] for s in states]).min() >= 0
    assert any(s["next"] is not None for s in states)


def test_the_last_state_says_how_the_mission_ended(watched) -> None:
    *_, feed = watched
    assert [s["ended"] for s in feed.states[:-1]] == [None] * (len(feed.states) - 1)
    assert feed.states[-1]["ended"] == "completed"
    assert feed.states[-1]["inspected"] >= 1


def test_a_team_cannot_be_watched_yet(tmp_path: Path) -> None:
    from seminspect.core.errors import InvalidInputError

    config = make_config(CONFIG | {"robots": ["explorer", "inspector"]})
    with pytest.raises(InvalidInputError, match="one robot"):
        run_mission(config, tmp_path / "team", watch=LiveWatch(_EveryFrame()))
    assert not (tmp_path / "team").exists()
