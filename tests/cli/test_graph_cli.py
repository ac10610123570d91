import json
from pathlib import Path

import pytest

from cli_runner import run
from seminspect.graphs.lsg.io import load_graph


def test_version_and_help(capsys) -> None:
    code, out, _ = run(capsys, "--version")
    assert code == 0 and out.startswith("seminspect ")
    code, out, _ = run(capsys, "graph", "--help")
    assert code == 0 and "query" in out and "export" in out


def test_info_prints_the_table_3_columns(capsys) -> None:
    code, out, _ = run(capsys, "graph", "info", "example")
    assert code == 0
    for column in ("Target", "Level", "Pose", "Feature", "Unified", "Reconciled"):
        assert column in out
    assert "truck-3" in out


def test_query_answers_the_papers_forms(capsys) -> None:
    code, out, _ = run(capsys, "graph", "query", "example", "Visit Level-1 of truck-3", "--json")
    assert code == 0
    answer = json.loads(out)
    assert answer["goal"] == "truck-3/Level-1"
    assert answer["target_route"][-1] == "truck-3"
    assert answer["length_m"] > 0 and answer["planning_time_s"]["total"] > 0
    code, out, _ = run(
        capsys, "graph", "query", "example", "observe front-bumper-1 in level 0 of CAR-1"
    )
    assert code == 0 and "then observe car-1/Level-0/front-bumper-1" in out


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("graph", "query", "example", "Visit car-77"), "unknown target 'car-77'"),
        (("graph", "query", "example", "Visit"), "names no node"),
        (("graph", "info", "missing.json"), "no such file"),
    ],
)
def test_errors_are_one_line_and_non_zero(capsys, args, message) -> None:
    code, _, err = run(capsys, *args)
    assert code == 1
    assert message in err and err.count("\n") == 1 and "Traceback" not in err


def test_export_formats(capsys, tmp_path: Path) -> None:
    for fmt, name in (("graphml", "g.graphml"), ("json", "g.json")):
        code, _, _ = run(
            capsys, "graph", "export", "example", "--format", fmt, "--out", str(tmp_path / name)
        )
        assert code == 0 and (tmp_path / name).stat().st_size > 0
    assert load_graph(tmp_path / "g.json").population().targets_inspected == 5
    code, _, err = run(capsys, "graph", "export", str(tmp_path / "g.json"), "-f", "json")
    assert code != 0 and "overwrite" in err


def test_show_draws_the_layers(capsys, tmp_path: Path) -> None:
    out = tmp_path / "g.png"
    code, _, _ = run(capsys, "graph", "show", "example", "--out", str(out), "-q", "Visit car-1")
    assert code == 0 and out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
