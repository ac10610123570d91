import json
import re
from pathlib import Path

import pytest

from cli_runner import run
from seminspect.graphs.lsg.io import example_graph_path, load_graph


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


EXAMPLE_TARGETS = ["car-0", "car-1", "car-2", "truck-3", "car-4"]


def node_name(line: str) -> str:
    """The first name on a tree line, after rich's guides (box-drawing or ASCII)."""
    found = re.search(r"[A-Za-z][\w.-]*", line)
    assert found, line
    return found.group()


def tree_lines(capsys, *options: str) -> list[str]:
    code, out, err = run(capsys, "graph", "tree", "example", *options)
    assert code == 0, err
    return out.splitlines()


def test_tree_prints_the_hierarchy_one_node_per_line(capsys) -> None:
    lines = tree_lines(capsys)
    graph = load_graph(example_graph_path())
    nodes = len(graph.targets()) + len(graph.levels()) + len(graph.poses())
    assert len(lines) == 1 + nodes + len(graph.features())  # the title, then a line per node
    assert lines[0] == "example: 5 targets"
    listed = [node_name(line) for line in lines[1:]]
    assert [name for name in listed if name in EXAMPLE_TARGETS] == EXAMPLE_TARGETS
    first = next(line for line in lines if "car-1  " in line)
    assert "car, inspected, 2 levels, (38.28, 16.24, 0.75), score 0.90" in first
    assert any("pose-1  (42.87, 18.31, 0.70), yaw -2.70, 2 features, car-1/L0/001.png" in line
               for line in lines)  # fmt: skip


@pytest.mark.parametrize(
    ("depth", "present", "absent"),
    [
        ("1", "truck-3  truck", "Level-0"),
        ("2", "Level-1  12 poses", "pose-0"),
        ("3", "pose-11  ", "back-glass-1"),
        ("4", "back-glass-1  back-glass, score", None),
    ],
)
def test_tree_depth_stops_at_a_layer(capsys, depth, present, absent) -> None:
    out = "\n".join(tree_lines(capsys, "--depth", depth))
    assert present in out
    assert absent is None or absent not in out


def test_tree_of_one_target(capsys) -> None:
    lines = tree_lines(capsys, "--target", "CAR-1", "-d", "2")
    assert lines[0] == "example: 1 target"
    assert [node_name(line) for line in lines[1:]] == ["car-1", "Level-0", "Level-1"]


@pytest.mark.parametrize(
    ("options", "message"),
    [(("--target", "car-77"), "unknown target 'car-77'"), (("--depth", "5"), "--depth")],
)
def test_tree_refuses_what_it_cannot_show(capsys, options, message) -> None:
    code, _, err = run(capsys, "graph", "tree", "example", *options)
    assert code != 0 and message in err and "Traceback" not in err


def test_export_csv_writes_a_table_per_layer(capsys, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    code, out, _ = run(capsys, "graph", "export", "example", "--format", "csv")
    assert code == 0 and "wrote 9 tables to example_graph_csv" in out
    graph = load_graph(example_graph_path())
    expected = {"targets": 5, "levels": 10, "poses": 120, "features": 200, "pose_edges": 130}
    for table, count in expected.items():
        lines = (tmp_path / "example_graph_csv" / f"{table}.csv").read_text().splitlines()
        assert len(lines) == 1 + count, table
    assert graph.population().pose.edges == expected["pose_edges"]
    code, _, _ = run(capsys, "graph", "export", "example", "-f", "csv", "-o", "mine")
    assert code == 0 and (tmp_path / "mine" / "features.csv").is_file()
    (tmp_path / "taken").write_text("")
    code, _, err = run(capsys, "graph", "export", "example", "-f", "csv", "-o", "taken")
    assert code == 1 and "taken is a file; give a folder" in err
