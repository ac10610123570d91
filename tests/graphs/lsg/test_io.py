import json
from pathlib import Path

import networkx as nx
import pytest
from hypothesis import HealthCheck, given, settings

from lsg_strategies import climbing_graphs, layered_graphs
from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.graphs.lsg import io as lsg_io
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.io import (
    export_graphml,
    export_spark_dsg,
    graph_document,
    load_graph,
    save_graph,
)
from seminspect.graphs.lsg.synthetic import synthetic_graph
from seminspect.perception.observation import Observation


def edge_table(graph: LayeredSemanticGraph) -> list[tuple]:
    return sorted(
        (e.u, e.v, e.kind.value, e.weight, None if e.via is None else e.via.tolist())
        for e in graph.edges()
    )


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(graph=layered_graphs())
def test_json_round_trip_is_lossless(tmp_path: Path, graph: LayeredSemanticGraph) -> None:
    path = save_graph(graph, tmp_path / "graph.json")
    loaded = load_graph(path)
    assert graph_document(loaded) == graph_document(graph)
    assert edge_table(loaded) == edge_table(graph)
    assert loaded.population() == graph.population()
    assert loaded.params == graph.params


@pytest.fixture(scope="module")
def saved(tmp_path_factory: pytest.TempPathFactory) -> dict:
    path = tmp_path_factory.mktemp("g") / "graph.json"
    save_graph(synthetic_graph(3, poses_per_level=4, levels=2), path)
    return json.loads(path.read_text())


def corrupt(document: dict, edit) -> dict:
    copy = json.loads(json.dumps(document))
    edit(copy)
    return copy


CASES = {
    "unit quaternion": (
        lambda d: d["targets"][0]["levels"][0]["poses"][0].update(orientation=[0, 0, 0, 3]),
        "not a unit quaternion",
    ),
    "short position": (
        lambda d: d["targets"][0].update(position=[1, 2]),
        r"targets\.0\.position",
    ),
    "string number": (lambda d: d["targets"][0].update(score="0.9"), r"targets\.0\.score"),
    "score range": (lambda d: d["targets"][0].update(score=7), "less than or equal to 1"),
    "slash in a label": (lambda d: d["targets"][0].update(label="car/x"), r"targets\.0\.label"),
    "extra field": (lambda d: d.update(payload="<script>"), "Extra inputs"),
    "name mismatch": (lambda d: d["targets"][1].update(name="car-0"), "expected '.*-1' here"),
    "level order": (
        lambda d: d["targets"][0]["levels"][0].update(name="Level-3"),
        "expected 'Level-0' here",
    ),
    "duplicate feature": (
        lambda d: d["targets"][0]["levels"][0]["poses"][1]["features"].append(
            d["targets"][0]["levels"][0]["poses"][0]["features"][0]
        ),
        "already exists",
    ),
    "edge to nowhere": (
        lambda d: d["target_edges"].append({"a": "car-0", "b": "car-9"}),
        "unknown target 'car-9'",
    ),
    "detected with levels": (
        lambda d: d["targets"][0].update(status="detected"),
        "has levels but is not inspected",
    ),
    "index counter": (lambda d: d.update(next_target_index=0), "next_target_index"),
    "bad params": (lambda d: d["params"].update(d_check_T=-4.0), "d_check_T"),
    "polygon": (lambda d: d["targets"][0].update(polygon=[[0, 0], [1, 1]]), "polygon"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_defective_files_give_one_clear_error(tmp_path: Path, saved: dict, case: str) -> None:
    edit, message = CASES[case]
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(corrupt(saved, edit)))
    with pytest.raises(FileFormatError, match=message) as info:
        load_graph(path)
    assert "\n" not in str(info.value)


def test_truncated_and_wrong_version_files(tmp_path: Path, saved: dict) -> None:
    text = json.dumps(saved)
    path = tmp_path / "t.json"
    path.write_text(text[: len(text) // 2])
    with pytest.raises(FileFormatError, match="malformed JSON"):
        load_graph(path)
    path.write_text(json.dumps({**saved, "version": 2}))
    with pytest.raises(FileFormatError, match="version 2 is not supported"):
        load_graph(path)


def test_a_graph_mid_inspection_is_not_saved_and_the_old_file_survives(tmp_path: Path) -> None:
    graph = synthetic_graph(2)
    path = save_graph(graph, tmp_path / "graph.json")
    before = path.read_bytes()
    graph.register_target(Observation([500, 500, 0], label="car", score=1, mask_area=1))
    graph.optimise_targets()
    graph.begin_inspection(graph.targets()[-1].id, Observation.view_pose([498, 500, 0]))
    with pytest.raises(InvalidInputError, match="being inspected"):
        save_graph(graph, path)
    assert path.read_bytes() == before


def test_graphml_export_is_readable_by_networkx(tmp_path: Path) -> None:
    graph = synthetic_graph(3, poses_per_level=4)
    path = export_graphml(graph, tmp_path / "g.graphml")
    read = nx.read_graphml(path)
    assert read.number_of_nodes() == graph.population().unified.nodes
    assert read.number_of_edges() == graph.population().unified.edges
    assert read.nodes["car-0/Level-0/pose-0"]["layer"] == "pose"


def test_spark_dsg_export_loads_in_spark_dsg(tmp_path: Path) -> None:
    spark_dsg = pytest.importorskip("spark_dsg")
    graph = synthetic_graph(3, poses_per_level=4, levels=2)
    path = export_spark_dsg(graph, tmp_path / "g.dsg.json")
    loaded = spark_dsg.DynamicSceneGraph.load(str(path))
    assert loaded.num_nodes() == graph.population().unified.nodes
    assert loaded.num_edges() == graph.population().unified.edges
    assert set(loaded.layer_names) == {"targets", "levels", "poses", "features"}
    names = {loaded.get_layer(name).num_nodes() for name in ("levels",)}
    assert names == {3 * 2}


@settings(
    max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(graph=climbing_graphs())
def test_open_rings_and_realised_level_edges_survive_a_round_trip(
    tmp_path: Path, graph: LayeredSemanticGraph
) -> None:
    loaded = load_graph(save_graph(graph, tmp_path / "graph.json"))
    assert edge_table(loaded) == edge_table(graph)
    assert graph_document(loaded) == graph_document(graph)


def test_a_graph_without_open_rings_or_level_routes_is_written_as_before(saved: dict) -> None:
    levels = [level for target in saved["targets"] for level in target["levels"]]
    assert levels and all("ring" not in level and "via" not in level for level in levels)


def test_files_over_the_size_limit_are_refused_before_reading(tmp_path, saved, monkeypatch) -> None:
    path = tmp_path / "big.json"
    path.write_text(json.dumps(saved))
    monkeypatch.setattr(lsg_io, "MAX_GRAPH_BYTES", path.stat().st_size - 1)
    with pytest.raises(FileFormatError, match="byte limit"):
        load_graph(path)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('{"format": "seminspect.lsg", "version": 1, "params": {"a": NaN}}', "non-standard JSON"),
        ('{"format": "seminspect.lsg", "version": 1, "targets": {}}', "expected a list of targets"),
        ("[" * 100_000, "nested too deeply"),
        ('{"format": "seminspect.other", "version": 1}', "found format 'seminspect.other'"),
        ('{"format": "seminspect.lsg", "version": 1.0}', "version 1.0 is not supported"),
        ('{"format": "seminspect.lsg", "version": true}', "version True is not supported"),
        ("\xff\xfe", "not UTF-8"),
    ],
)
def test_hostile_json_is_one_clear_line(tmp_path, text, message) -> None:
    path = tmp_path / "hostile.json"
    path.write_bytes(text.encode("latin-1"))
    with pytest.raises(FileFormatError, match=message) as info:
        load_graph(path)
    assert "\n" not in str(info.value)
    with pytest.raises(FileFormatError, match="is a directory"):
        load_graph(tmp_path)
