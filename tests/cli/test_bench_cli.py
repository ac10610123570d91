from pathlib import Path

import pytest

from cli_runner import run
from seminspect.studies.xflie import study as planning_study
from study_fakes import study


def test_the_planning_study_writes_its_tables_figure_and_json(capsys, tmp_path, monkeypatch):
    calls = {}

    def fake_study(scenarios, runs_dir, **options):
        calls.update(scenarios=scenarios, runs_dir=runs_dir, **options)
        options["progress"]("Table 5 mission: large", None)
        return study(vp_s=0.06)

    monkeypatch.setattr(planning_study, "run_study", fake_study)
    out = tmp_path / "bench"
    code, text, _ = run(
        capsys, "bench", "planning", "-s", "large", "-s", "large", "--out", str(out),
        "--size", "50", "--size", "20", "--no-missions", "--volume", "full", "--seeds", "2",
    )  # fmt: skip
    assert code == 0
    assert calls["scenarios"] == ["large"] and calls["runs_dir"] == out / "runs"
    assert calls["sizes"] == [20, 50] and calls["missions"] is False and calls["queries"] == 9
    assert calls["volume"] == "full" and calls["seeds"] == [0, 1]
    for name in ("planning.md", "planning.json", "scaling.png"):
        assert (out / name).stat().st_size > 0 and str(out / name) in text


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--scenario", "huge"), "'huge' is not one of"),
        (("--queries", "0"), "--queries"),
        (("--size", "1"), "at least 2 vehicles"),
        (("--volume", "sky"), "'sky' is not one of"),
        (("--seeds", "0"), "--seeds"),
    ],
)
def test_bad_study_settings_exit_non_zero_with_one_line(capsys, tmp_path, args, message) -> None:
    code, _, err = run(capsys, "bench", "planning", *args, "--out", str(tmp_path / "b"))
    assert code != 0 and message in err and "Traceback" not in err
    assert err.strip().count("\n") == 0
    assert not Path(tmp_path / "b").exists()
