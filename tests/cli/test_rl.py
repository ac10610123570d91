"""``seminspect rl``: evaluate and show baselines, and one-line errors."""

import socket

import pytest

from cli_runner import run
from seminspect.core.io import file_sha256
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.evaluation import EvaluationResult, evaluation_config


def test_eval_writes_the_json_the_pictures_the_report_and_a_table_beside_table_1(capsys, tmp_path):
    out = tmp_path / "eval"
    code, stdout, err = run(
        capsys, "rl", "eval", "--policy", "orbit", "--obstacles", "0,14", "--episodes", "1",
        "--envs", "1", "--shapes", "box", "--out", str(out),
    )  # fmt: skip
    assert code == 0, err
    result = EvaluationResult.from_json(out / "evaluation.json")
    assert [r.obstacles for r in result.results] == [0, 14]
    assert result.policy == "orbit" and result.at(0).episodes == 1
    assert result.checkpoint_sha256 is None  # a baseline
    assert result.config == evaluation_config(EnvConfig(), ("box",))  # the protocol's rooms
    assert (out / "coverage.png").exists() and (out / "episode_14_3d.png").exists()
    assert "92.1" in stdout and "64.2" in stdout and "1.5" in stdout  # 004 Table I beside ours
    row = result.at(14)
    assert f"{row.coverage_pct:.1f}" in stdout
    low, high = row.strict_coverage_ci
    assert f"{row.strict_coverage_pct:.1f} [{low:.1f}-{high:.1f}]" in stdout
    assert f"{row.crash_pct:.1f} [{row.crash_ci[0]:.1f}-{row.crash_ci[1]:.1f}]" in stdout
    assert row.crashed == [True]  # the orbit meets an obstacle in this room
    assert f"crashes at 14 obstacles struck: {row.struck[0]} 1" in stdout
    page = (out / "report.html").read_text(encoding="utf-8")
    assert "plotly" in page and "004 Table I" in page
    pictures = len(list(out.glob("*.png")))
    assert pictures == 7  # coverage.png and three per obstacle count
    line = f"results: {out}  (report.html, evaluation.json, {pictures} pictures (*.png))"
    assert line in stdout  # on one line, naming only what exists


def test_show_draws_one_episode(capsys, tmp_path):
    code, stdout, err = run(
        capsys, "rl", "show", "--policy", "random", "--obstacles", "0", "--out", str(tmp_path)
    )
    assert code == 0, err
    assert "coverage" in stdout
    assert {p.name for p in tmp_path.iterdir()} == {
        "episode_top.png", "episode_3d.png", "episode_coverage.png"
    }  # fmt: skip


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--obstacles", "0,a"], "comma-separated whole numbers"),
        (["--obstacles", "4,4"], "repeats"),
        (["--obstacles", "0,99"], "must lie in 0-60"),
        (["--episodes", "0"], "--episodes must be at least 1"),
        (["--policy", "greedy"], "unknown policy 'greedy'"),
        (["--shapes", "cylinder,torus"], "unknown shape 'torus'"),
        (["--shapes", "box,box"], "--shapes repeats a shape"),
    ],
)
def test_bad_input_is_one_line_and_exit_1(capsys, tmp_path, args, message):
    code, _, err = run(capsys, "rl", "eval", *args, "--out", str(tmp_path / "x"))
    assert code == 1
    assert message in err and "Traceback" not in err
    assert len(err.strip().splitlines()) <= 2  # rich may wrap the one line


def test_an_unwritable_out_is_refused_before_any_work(capsys, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    code, _, err = run(capsys, "rl", "eval", "--policy", "random", "--out", str(blocker))
    assert code == 1 and "not a directory" in err


def test_train_writes_a_checkpoint_that_eval_can_fly(capsys, tmp_path):
    run_dir = tmp_path / "run"
    code, stdout, err = run(
        capsys, "rl", "train", "--steps", "256", "--envs", "4", "--out", str(run_dir)
    )
    assert code == 0, err
    assert (run_dir / "checkpoint.pt").is_file() and (run_dir / "progress.csv").is_file()
    assert "256 steps" in stdout
    code, _, err = run(
        capsys, "rl", "eval", "--policy", str(run_dir / "checkpoint.pt"), "--obstacles", "0",
        "--episodes", "1", "--envs", "1", "--out", str(tmp_path / "eval"),
    )  # fmt: skip
    assert code == 0, err
    result = EvaluationResult.from_json(tmp_path / "eval" / "evaluation.json")
    assert result.at(0).episodes == 1
    assert result.checkpoint_sha256 == file_sha256(run_dir / "checkpoint.pt")
    from seminspect.missions.learning.checkpoints import read_checkpoint

    trained = read_checkpoint(run_dir / "checkpoint.pt").env_config
    assert result.config == evaluation_config(trained)  # what it saw in training, our rooms
    tuned_dir = tmp_path / "tuned"
    parent = run_dir / "checkpoint.pt"
    code, stdout, err = run(
        capsys, "rl", "train", "--init-from", str(parent), "--steps", "256", "--envs", "4",
        "--out", str(tuned_dir),
    )  # fmt: skip
    assert code == 0, err
    tuned = read_checkpoint(tuned_dir / "checkpoint.pt")
    assert tuned.train_config is not None and tuned.train_config.init_from == file_sha256(parent)
    assert tuned.train_config.curriculum == ((0.0, 9),)  # nine obstacles from the first step


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--variant", "gru9"], "unknown variant 'gru9'"),
        (["--config", "huge"], "unknown network size 'huge'"),
        (["--envs", "6"], "multiple of minibatches"),
        (["--device", "gpu"], "not a torch device"),
        (["--steps", "0"], "--steps must be at least 1"),
        (["--init-from", "missing.pt"], "no such file"),
        (["--init-from", "missing.pt", "--variant", "no-gru"], "drop --config and --variant"),
    ],
)
def test_train_refuses_bad_settings_in_one_line(capsys, tmp_path, args, message):
    code, _, err = run(capsys, "rl", "train", *args, "--out", str(tmp_path / "x"))
    assert code == 1
    assert message in err and "Traceback" not in err
    assert not (tmp_path / "x" / "checkpoint.pt").exists()


def test_without_torch_the_learned_policy_says_how_to_get_it(capsys, tmp_path, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "torch", None)  # import torch raises ImportError
    code, _, err = run(capsys, "rl", "eval", "--out", str(tmp_path / "x"))
    assert code == 1
    assert "pip install 'seminspect[rl]'" in err and "Traceback" not in err


def test_show_view_on_a_port_in_use_is_one_line_before_the_episode(capsys, tmp_path):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        code, _, err = run(
            capsys, "rl", "show", "--policy", "random", "--view", "--view-port", str(port),
            "--out", str(tmp_path / "show"),
        )  # fmt: skip
    assert code == 1 and f"cannot serve the live view on 127.0.0.1:{port}" in err
    assert "Traceback" not in err and not (tmp_path / "show").exists()


@pytest.mark.slow
def test_show_view_flies_the_same_episode(capsys, tmp_path, monkeypatch):
    monkeypatch.setattr("seminspect.cli._common.VIEW_WAIT_S", 0.1)
    args = ("rl", "show", "--policy", "random", "--obstacles", "9", "--seed", "3")
    code, plain, err = run(capsys, *args, "--out", str(tmp_path / "plain"))
    assert code == 0, err
    code, seen, err = run(
        capsys, *args, "--view", "--view-port", "0", "--out", str(tmp_path / "seen")
    )
    assert code == 0, err
    assert "live view at http://127.0.0.1:" in err
    assert seen.splitlines()[0] == plain.splitlines()[0]  # the same coverage and ending
    assert "crashed" in seen
