import pytest

from seminspect.missions.rundir import load_trajectory
from seminspect.report.run_pictures import load_events, render_run


@pytest.mark.slow
def test_pictures_are_drawn_from_the_run_directory_alone(small_mission_dir) -> None:
    written = render_run(small_mission_dir)
    assert [p.name for p in written] == ["trajectory.png", "graph.png", "utility.png"]
    for path in written:
        assert path.read_bytes()[:4] == b"\x89PNG" and path.stat().st_size > 20_000
    assert load_trajectory(small_mission_dir).shape[1] == 9
    assert any(e["event"] == "utilities" for e in load_events(small_mission_dir))
