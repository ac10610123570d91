"""The layers of a 3DLSG as rows, CSV files and networkx graphs."""

from __future__ import annotations

import csv
from pathlib import Path

import networkx as nx
import numpy as np
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.graphs.lsg import (
    Layer,
    LayeredSemanticGraph,
    TargetStatus,
    example_graph_path,
    export_csv,
    layer_edge_rows,
    layer_networkx,
    layer_rows,
    load_graph,
    synthetic_graph,
    to_networkx,
)
from seminspect.graphs.lsg.tables import COLUMNS, EDGE_COLUMNS
from seminspect.perception.observation import Observation


def synthetic_with_extras() -> LayeredSemanticGraph:
    """Inspected vehicles, one more only detected, and a ``v_I - v_I`` edge through via points."""
    graph = synthetic_graph(6, seed=5, poses_per_level=7, levels=2)
    graph.register_target(Observation([900.0, 900.0, 0.7], label="van", score=0.4, mask_area=7))
    graph.optimise_targets()
    inspected = [t.id for t in graph.targets(TargetStatus.INSPECTED)]
    a, b = next((a, b) for a in inspected for b in inspected if a < b and not graph.edge(a, b))
    graph.connect_targets(a, b, via=[[1.0, 2.0, 0.7], [3.0, 4.0, 0.7]])
    return graph


GRAPHS = {"example": lambda: load_graph(example_graph_path()), "synthetic": synthetic_with_extras}


@pytest.fixture(scope="module", params=sorted(GRAPHS))
def graph(request: pytest.FixtureRequest) -> LayeredSemanticGraph:
    return GRAPHS[request.param]()


def read_csv(path: Path) -> tuple[list[str], list[dict[str, str]]]:
    with path.open(newline="", encoding="utf-8") as handle:
        reader = csv.DictReader(handle)
        return list(reader.fieldnames or []), list(reader)


@pytest.mark.parametrize("layer", list(Layer))
def test_rows_have_the_documented_columns_and_the_layers_population(graph, layer) -> None:
    rows, edges = layer_rows(graph, layer), layer_edge_rows(graph, layer)
    counted = getattr(graph.population(), layer.value)
    assert all(tuple(row) == COLUMNS[layer] for row in rows)
    assert len(rows) == counted.nodes - len(graph.local_graphs(layer))  # parents borrowed
    assert len(edges) == counted.edges
    assert all(tuple(row) == EDGE_COLUMNS for row in edges)


@pytest.mark.parametrize("layer", list(Layer))
def test_a_layer_as_networkx_has_the_nodes_and_edges_its_population_counts(graph, layer) -> None:
    counted = getattr(graph.population(), layer.value)
    view = layer_networkx(graph, layer)
    assert (view.number_of_nodes(), view.number_of_edges()) == (counted.nodes, counted.edges)
    parents = {local.parent.id for local in graph.local_graphs(layer)}
    own = [node for node in view if node not in parents]
    assert own == [row["id"] for row in layer_rows(graph, layer)]


def test_the_layers_together_are_the_unified_graph(graph) -> None:
    union = nx.compose_all([layer_networkx(graph, layer) for layer in Layer])
    unified = to_networkx(graph)
    assert set(union.nodes) == set(unified.nodes)
    assert {frozenset(e) for e in union.edges} == {frozenset(e) for e in unified.edges}


def test_a_pose_row_and_node_carry_its_parent_and_attributes(graph) -> None:
    pose = graph.poses()[3]
    row = next(r for r in layer_rows(graph, Layer.POSE) if r["id"] == pose.id)
    assert row["parent"] == pose.level.id and row["target"] == pose.level.target.id
    assert [row[k] for k in ("x", "y", "z")] == pose.position.tolist()
    assert [row[k] for k in ("qx", "qy", "qz", "qw")] == pose.orientation.tolist()
    attrs = layer_networkx(graph, Layer.POSE).nodes[pose.id]
    assert attrs["parent"] == pose.level.id and attrs["features"] == len(pose.features)


def test_csv_tables_read_back_to_the_graphs_numbers(graph, tmp_path: Path) -> None:
    written = export_csv(graph, tmp_path / "tables")
    assert sorted(p.name for p in written) == sorted(
        [f"{layer.value}s.csv" for layer in Layer]
        + [f"{layer.value}_edges.csv" for layer in Layer]
        + ["polygons.csv"]
    )
    for layer in Layer:
        header, rows = read_csv(tmp_path / "tables" / f"{layer.value}s.csv")
        assert tuple(header) == COLUMNS[layer]
        assert len(rows) == len(layer_rows(graph, layer))
    _, features = read_csv(tmp_path / "tables" / "features.csv")
    for row, feature in zip(features, graph.features(), strict=True):
        assert row["id"] == feature.id and row["parent"] == feature.pose.id
        assert [float(row[k]) for k in ("x", "y", "z")] == feature.position.tolist()  # exact
        assert float(row["score"]) == feature.score and row["image"] == (feature.image or "")
    _, polygons = read_csv(tmp_path / "tables" / "polygons.csv")
    for target in graph.targets(TargetStatus.INSPECTED):
        vertices = [(float(r["x"]), float(r["y"])) for r in polygons if r["target"] == target.id]
        np.testing.assert_array_equal(vertices, target.polygon)


def test_edge_tables_keep_weights_and_count_via_points(graph, tmp_path: Path) -> None:
    export_csv(graph, tmp_path)
    _, rows = read_csv(tmp_path / "target_edges.csv")
    realised = [e for e in graph.target_graph.edges.values() if e.via is not None]
    assert sum(int(row["via_points"]) > 0 for row in rows) == len(realised)
    for row in rows:
        edge = graph.edge(row["u"], row["v"])
        assert edge is not None and float(row["weight"]) == edge.weight
        assert int(row["via_points"]) == (0 if edge.via is None else len(edge.via))


def test_the_synthetic_graph_has_what_the_tables_must_carry() -> None:
    graph = synthetic_with_extras()
    assert graph.targets(TargetStatus.DETECTED)
    assert any(e.via is not None for e in graph.target_graph.edges.values())


def test_pandas_reads_the_tables_when_it_is_installed(tmp_path: Path) -> None:
    pandas = pytest.importorskip("pandas")
    graph = load_graph(example_graph_path())
    export_csv(graph, tmp_path)
    poses = pandas.read_csv(tmp_path / "poses.csv")
    assert list(poses.columns) == list(COLUMNS[Layer.POSE]) and len(poses) == 120
    assert poses.groupby("parent").size().to_dict() == {lv.id: 12 for lv in graph.levels()}


def test_a_file_where_the_folder_should_be_is_refused(tmp_path: Path) -> None:
    (tmp_path / "tables").write_text("not a folder")
    with pytest.raises(InvalidInputError, match="tables is a file; give a folder"):
        export_csv(load_graph(example_graph_path()), tmp_path / "tables")
