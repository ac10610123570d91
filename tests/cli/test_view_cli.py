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
