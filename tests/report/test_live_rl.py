"""The live view of a policy episode: its messages say what the episode holds, and in a real
browser the page fills and updates while an episode is flown and ends with its own counts."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from live_pages import RecordingServer, grew, watch_in_browser
from seminspect.missions.learning.baselines import OrbitController, RandomController
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.live import EpisodeRun, LiveWatch, play_episode
from seminspect.missions.learning.rooms import TARGET_FACES
from seminspect.report.live_rl import (
    COVERED,
    FAR,
    STRICT,
    UNSEEN,
    EpisodeFeed,
    episode_page,
)
from seminspect.report.live_server import LiveServer

SHORT = EnvConfig(obstacles=4, episode_seconds=8.0)
TRACES = ("room", "obstacles", "object", "faces", "path", "robot")


@pytest.fixture(scope="module")
def feed_messages() -> tuple[RecordingServer, EpisodeRun]:
    server = RecordingServer()
    feed = EpisodeFeed(server)  # type: ignore[arg-type]
    flown = play_episode(OrbitController(), SHORT, seed=2, watch=LiveWatch(feed))
    return server, flown


def test_the_scene_is_the_room_its_obstacles_and_the_objects_faces(feed_messages) -> None:
    server, flown = feed_messages
    scene, room = server.scene, flown.trace.room
    assert scene is not None
    traces = scene["traces"]
    assert max(v for v in traces["room"]["x"] if v is not None) == pytest.approx(room.size[0])
    target = room.face_of_triangle >= 0
    assert len(traces["object"]["i"]) == int(target.sum())
    obstacles = traces["obstacles"]
    assert 0 < len(obstacles["i"]) < int((~target).sum())  # the room's shell left out
    assert max(obstacles["i"] + obstacles["j"] + obstacles["k"]) == len(obstacles["x"]) - 1
    assert len(traces["faces"]["x"]) == len(traces["faces"]["text"]) == TARGET_FACES
    assert scene["faces"] == TARGET_FACES and 0 < scene["feasible"] <= TARGET_FACES


def test_messages_are_the_episode_as_it_stood(feed_messages) -> None:
    server, flown = feed_messages
    sent = server.sent
    assert [m["step"] for m in sent] == [*range(flown.steps + 1), flown.steps]
    first, last = sent[0], sent[-1]
    assert first["final"] is None and first["reward"] == 0.0
    assert last["final"] == "episode timeout: 8 s flown without a crash"
    track = flown.trace.track
    assert len(last["traces"]["path"]["x"]) == len(track)
    assert last["pose"] == pytest.approx(track[-1, :4].tolist(), abs=1e-3)
    assert last["return"] == pytest.approx(flown.episode_return, abs=1e-3)
    assert last["coverage"] == pytest.approx(flown.coverage, abs=1e-4)
    covered = int((flown.trace.face_distances <= SHORT.inspect_range).sum())
    assert last["covered"] == covered and last["strict"] == int(flown.strict.sum())
    colours = last["traces"]["faces"]["color"]
    assert len(colours) == TARGET_FACES and colours.count(STRICT) == last["strict"]
    assert colours.count(STRICT) + colours.count(COVERED) == covered
    assert set(first["traces"]["faces"]["color"]) <= {UNSEEN, FAR}
    assert all(m["image"].startswith("data:image/jpeg;base64,") for m in sent)
    status = dict(last["status"])
    assert status["step"] == f"{flown.steps} / {SHORT.steps_per_episode}"
    assert status["coverage"].startswith(f"{100 * flown.coverage:.1f} % ({covered} of 60")
    assert status["episode"].startswith("timeout")


def test_a_crash_says_what_it_struck() -> None:
    server = RecordingServer()
    config = EnvConfig(obstacles=0, episode_seconds=30.0)
    flown = play_episode(
        RandomController(0),
        config,
        seed=0,
        watch=LiveWatch(EpisodeFeed(server)),  # type: ignore[arg-type]
    )
    assert flown.ending == "crashed"
    assert server.sent[-1]["final"].startswith("episode crashed: struck the ")


@pytest.mark.slow
def test_the_live_view_updates_in_a_browser(tmp_path: Path) -> None:
    config = EnvConfig(obstacles=4, episode_seconds=30.0)
    flown: list[EpisodeRun] = []

    def episode(server: LiveServer) -> None:
        watch = LiveWatch(EpisodeFeed(server))
        flown.append(play_episode(OrbitController(), config, seed=2, watch=watch))

    colours_js = f"() => document.getElementById('live-scene').data[{TRACES.index('faces')}]"
    seen = watch_in_browser(
        episode_page("live test"), episode, "episode timeout", tmp_path / "live.png",
        {"colours": colours_js + ".marker.color"},
    )  # fmt: skip
    final, colours, times = seen.final, seen.values["colours"], [t for t, _ in seen.states]
    assert seen.errors == []
    assert flown and flown[0].ending == "timeout"
    assert set(final) == set(TRACES)
    assert final["room"] > 10 and final["obstacles"] > 0 and final["object"] > 0
    assert final["faces"] == TARGET_FACES and final["robot"] == 1
    assert grew(seen.states) and seen.states[-1][1] == len(flown[0].trace.track)
    assert isinstance(colours, list) and colours.count(STRICT) == int(flown[0].strict.sum())
    assert np.isclose(times[-1], config.episode_seconds)
    assert seen.camera is not None and seen.camera.startswith("data:image/jpeg;base64,")
    assert "strict" in seen.status and "timeout" in seen.status
    assert (tmp_path / "live.png").stat().st_size > 20_000
