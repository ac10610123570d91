import http.server
import shutil
import threading
import urllib.request

import pytest

from cli_runner import run
from seminspect.cli.view import make_server


def test_the_server_answers_on_localhost_only(tmp_path) -> None:
    (tmp_path / "report.html").write_text("<html>run</html>", encoding="utf-8")
    server = make_server(tmp_path, 0)
    host, port = server.server_address[:2]
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/report.html", timeout=10) as reply:
            assert reply.read() == b"<html>run</html>"
    finally:
        server.shutdown()
        server.server_close()
    assert host == "127.0.0.1"


def test_view_draws_a_missing_report_then_serves_it(
    capsys, tmp_path, small_mission_dir, monkeypatch: pytest.MonkeyPatch
) -> None:
    run_dir = tmp_path / "run"
    shutil.copytree(small_mission_dir, run_dir)
    (run_dir / "report.html").unlink(missing_ok=True)

    def stop(self) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(http.server.ThreadingHTTPServer, "serve_forever", stop)
    code, out, err = run(capsys, "view", str(run_dir), "--port", "0", "--no-browser")
    assert code == 0, err
    assert "http://127.0.0.1:" in out and "stopped" in out
    assert "plotly" in (run_dir / "report.html").read_text(encoding="utf-8")


def test_view_refuses_what_is_not_a_run(capsys, tmp_path) -> None:
    code, _, err = run(capsys, "view", str(tmp_path / "nowhere"), "--no-browser")
    assert code == 1 and "is not a directory" in err and "Traceback" not in err
    code, _, err = run(capsys, "view", str(tmp_path), "--no-browser")
    assert code == 1 and "no graph.json" in err and len(err.strip().splitlines()) == 1
    for looked_for in ("routine metrics.json", "evaluation.json (rl eval)"):
        assert looked_for in err  # says what it looked for, not only a mission's graph


def test_view_draws_the_report_of_an_rl_evaluation(
    capsys, tmp_path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from seminspect.missions.learning.baselines import OrbitController
    from seminspect.missions.learning.env import EnvConfig
    from seminspect.missions.learning.evaluation import evaluate

    short = EnvConfig(episode_seconds=1.0)
    evaluate(OrbitController(), [0], 1, 0, config=short, num_envs=1).to_json(
        tmp_path / "evaluation.json"
    )

    def stop(self) -> None:
        raise KeyboardInterrupt

    monkeypatch.setattr(http.server.ThreadingHTTPServer, "serve_forever", stop)
    code, out, err = run(capsys, "view", str(tmp_path), "--port", "0", "--no-browser")
    assert code == 0, err
    assert "serving" in out and "stopped" in out
    assert "004 Table I" in (tmp_path / "report.html").read_text(encoding="utf-8")


def test_view_help_names_every_run_kind(capsys) -> None:
    code, out, _ = run(capsys, "view", "--help")
    assert code == 0
    for kind in ("mission", "terrain", "routine", "rl eval"):
        assert kind in out


# --- --screenshot ------------------------------------------------------------------------------


def _refused(capsys, *args: str) -> str:
    """stderr of a ``seminspect view`` that must fail in one line, without a traceback."""
    code, _, err = run(capsys, "view", *args)
    assert code == 1 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    return err


def test_a_screenshot_that_is_no_png_or_has_no_folder_is_refused_before_drawing(
    capsys, tmp_path
) -> None:
    err = _refused(capsys, str(tmp_path), "--screenshot", str(tmp_path / "shot.jpg"))
    assert "shot.jpg" in err and "*.png" in err
    err = _refused(capsys, str(tmp_path), "--screenshot", str(tmp_path / "absent" / "shot.png"))
    assert "does not exist" in err and "absent" in err
    (tmp_path / "taken.png").mkdir()
    assert "is a directory" in _refused(
        capsys, str(tmp_path), "--screenshot", str(tmp_path / "taken.png")
    )
    # refused before report.html was drawn (this directory is no run: that would be the error)
    assert not (tmp_path / "report.html").exists()


def test_a_screenshot_without_playwright_says_how_to_install_it(
    capsys, tmp_path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import sys

    monkeypatch.setitem(sys.modules, "playwright", None)  # import playwright now fails
    err = _refused(capsys, str(tmp_path), "--screenshot", str(tmp_path / "shot.png"))
    assert "playwright" in err and "pip install 'seminspect[view]'" in err


def test_a_screenshot_without_chromium_says_how_to_get_one(
    capsys, tmp_path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from seminspect.report import browser

    monkeypatch.setattr(browser, "playwright_api", lambda: None)  # as if it were installed
    monkeypatch.setattr(browser, "find_chromium", lambda: None)
    err = _refused(capsys, str(tmp_path), "--screenshot", str(tmp_path / "shot.png"))
    assert "no Chromium found" in err and "SEMINSPECT_CHROMIUM" in err
    assert not (tmp_path / "shot.png").exists()


@pytest.mark.slow
def test_view_screenshot_writes_a_png_of_the_whole_page_and_serves_nothing(
    capsys, tmp_path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import cv2
    import numpy as np

    from seminspect.report.browser import VIEWPORT, find_chromium

    if find_chromium() is None:
        pytest.skip("no Chromium found (apt-get install chromium, or set $SEMINSPECT_CHROMIUM)")
    pytest.importorskip("playwright.sync_api", reason="playwright is not installed")
    # a page three screens tall stands in for a report (the report tests draw real ones)
    rows = "".join(f"<p style='height: 100px'>row {i}</p>" for i in range(30))
    (tmp_path / "report.html").write_text(f"<html><body>{rows}</body></html>", encoding="utf-8")

    def serve(self) -> None:
        raise AssertionError("--screenshot must not serve")

    monkeypatch.setattr(http.server.ThreadingHTTPServer, "serve_forever", serve)
    shots = tmp_path / "shots"
    shots.mkdir()
    code, out, err = run(capsys, "view", str(tmp_path), "--screenshot", str(shots / "run.png"))
    assert code == 0, err
    assert f"wrote {shots / 'run.png'}" in out and "warning" not in err
    png = (shots / "run.png").read_bytes()
    picture = cv2.imdecode(np.frombuffer(png, np.uint8), cv2.IMREAD_COLOR)
    assert picture.shape[1] == VIEWPORT["width"] and picture.shape[0] > 2 * VIEWPORT["height"]
    assert [p.name for p in shots.iterdir()] == ["run.png"]  # written atomically: no leftovers
