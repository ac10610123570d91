from pathlib import Path

import pytest

from cli_runner import run


@pytest.mark.slow
def test_mission_runs_and_says_where_the_results_are(capsys, tmp_path: Path) -> None:
    out = tmp_path / "tunnel"
    code, text, _ = run(
        capsys, "mission", "--world", "subterranean", "--out", str(out), "--query", "Visit car-0"
    )
    assert code == 0
    assert "completed" in text and str(out) in text and "query 'Visit car-0': reached" in text
    for picture in ("trajectory.png", "graph.png", "utility.png"):
        assert (out / picture).read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("mission", "--world", "atlantis"), "unknown world 'atlantis'"),
        (("mission", "--preset", "urban"), "preset"),
        (("mission", "--seed", "-3"), "--seed"),
    ],
)
def test_bad_mission_settings_exit_non_zero_with_one_line(capsys, tmp_path, args, message) -> None:
    code, _, err = run(capsys, *args, "--out", str(tmp_path / "run"))
    assert code != 0 and message in err and "Traceback" not in err
    assert err.strip().count("\n") == 0  # one line
