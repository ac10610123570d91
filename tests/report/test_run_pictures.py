import matplotlib.pyplot as plt
import pytest

from seminspect.report.run_pictures import render_run, timeline_figure
from seminspect.runs.directory import load_events
from seminspect.runs.trajectory import load_trajectory


@pytest.mark.slow
def test_pictures_are_drawn_from_the_run_directory_alone(small_mission_dir) -> None:
    written = render_run(small_mission_dir)
    assert [p.name for p in written] == ["trajectory.png", "graph.png", "utility.png"]
    for path in written:
        assert path.read_bytes()[:4] == b"\x89PNG" and path.stat().st_size > 20_000
    assert load_trajectory(small_mission_dir).shape[1] == 9
    assert any(e["event"] == "utilities" for e in load_events(small_mission_dir))


def test_the_timeline_draws_one_row_per_robot_and_one_bar_per_step() -> None:
    steps = [
        ("explorer", "survey", 0.0, 8.0),
        ("inspector", "wait", 0.0, 8.0),
        ("explorer", "explore", 8.0, 40.0),
        ("inspector", "inspect", 8.0, 120.0),
    ]
    events = [
        {"t": end, "event": "activity", "robot": r, "activity": a, "start": start, "end": end}
        for r, a, start, end in steps
    ] + [{"t": 3.0, "event": "detected", "robot": "explorer"}]
    figure = timeline_figure(events)
    ax = figure.axes[0]
    assert [t.get_text() for t in ax.get_yticklabels()] == ["explorer", "inspector"]
    bars = [p for p in ax.patches if p.get_width() > 0]
    assert sorted((round(p.get_x()), round(p.get_width())) for p in bars) == [
        (0, 8), (0, 8), (8, 32), (8, 112),
    ]  # fmt: skip
    plt.close(figure)
