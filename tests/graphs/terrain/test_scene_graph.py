import copy
import json

import networkx as nx
import numpy as np
import pytest
import shapely

from seminspect.core.errors import FileFormatError, InvalidInputError, PlanningError
from seminspect.graphs.terrain.evaluate import score_places
from seminspect.graphs.terrain.io import (
    load_terrain_graph,
    save_terrain_graph,
    write_graphml,
)
from seminspect.graphs.terrain.navigation import nearest_place, shortest_route
from seminspect.graphs.terrain.params import make_terrain_params
from seminspect.graphs.terrain.prompting import TaskPrompts
from seminspect.graphs.terrain.scene_graph import build_terrain_graph
from seminspect.mapping.formats.pointfiles import PointData
from seminspect.mapping.ingest import cloud_from_point_data

PROMPTS = TaskPrompts.parse("sidewalk,grass,asphalt", "image of a tree,image of a car")


@pytest.fixture(scope="module")
def build(labelled_scene, fake_encoder):
    fake = fake_encoder
    points, labels, names = labelled_scene
    cloud = cloud_from_point_data(PointData(points, labels=labels, label_names=names), fake)
    return build_terrain_graph(cloud, PROMPTS, fake)


def test_all_five_layers(build) -> None:
    scene = build.scene
    counts = scene.layer1_counts
    assert counts["asphalt"] > 0 and counts["sidewalk"] > 0 and counts["grass"] > 0
    labels = [scene.graph.nodes[n]["label"] for n in scene.nodes_of("object")]
    assert labels.count("image of a car") == 3 and labels.count("image of a tree") == 2
    for node in scene.nodes_of("object"):
        data = scene.graph.nodes[node]
        assert np.all(data["bbox_min"] <= data["position"]) and data["points"] > 0
        anchors = [m for m in scene.graph[node] if scene.graph.nodes[m]["kind"] == "place"]
        assert len(anchors) == 1
    terrains = {scene.graph.nodes[n]["terrain"] for n in scene.nodes_of("place")}
    assert terrains == {"sidewalk", "grass", "asphalt"}
    assert scene.nodes_of("region") and scene.nodes_of("map") == ["map"]
    assert nx.is_connected(scene.graph)
    assert set(build.timings) == {"prompts", "objects", "places", "regions", "assemble"}


def test_every_terrain_patch_gets_a_connected_place_graph_on_its_terrain(build) -> None:
    scene, graph = build.scene, build.scene.graph
    for terrain in scene.prompts.terrain:
        mine = [n for n in scene.nodes_of("place") if graph.nodes[n]["terrain"] == terrain]
        sub = nx.Graph((a, b) for a, b, d in graph.subgraph(mine).edges(data=True))
        sub.add_nodes_from(mine)
        assert nx.is_connected(sub), terrain
    # no place node off its terrain: the cell under it belongs to that terrain's grid
    for node in scene.nodes_of("place"):
        data = graph.nodes[node]
        assert build.places.gvd[data["terrain"]].cleaned[tuple(data["cell"])]


def test_json_round_trip_and_graphml(build, tmp_path) -> None:
    path = save_terrain_graph(tmp_path / "graph.json", build.scene, layer1_file="layer1.npz")
    again = load_terrain_graph(path)
    assert set(again.graph.nodes) == set(build.scene.graph.nodes)
    assert again.graph.number_of_edges() == build.scene.graph.number_of_edges()
    node = again.nodes_of("object")[0]
    np.testing.assert_allclose(
        again.graph.nodes[node]["bbox_max"], build.scene.graph.nodes[node]["bbox_max"]
    )
    np.testing.assert_array_equal(again.layer1.classes, build.scene.layer1.classes)
    assert again.params == build.scene.params
    flat = nx.read_graphml(write_graphml(tmp_path / "graph.graphml", build.scene))
    assert flat.number_of_nodes() == again.graph.number_of_nodes()
    assert "position_x" in flat.nodes["map"]


@pytest.mark.parametrize(
    "mutate",
    [
        lambda d: d["nodes"][0].update(position=[0, 0]),
        lambda d: d["nodes"][0].update(kind="castle"),
        lambda d: d["edges"].append({"source": "map", "target": "ghost", "kind": "map-region"}),
        lambda d: d.update(layer1_file="../../etc/passwd"),
        lambda d: d["nodes"].append(dict(d["nodes"][0])),
        lambda d: d.update(version=99),
        lambda d: d["params"].update(cell_size=-1),
    ],
)
def test_hostile_or_broken_json_is_refused(build, tmp_path, mutate) -> None:
    path = save_terrain_graph(tmp_path / "graph.json", build.scene)
    document = json.loads(path.read_text())
    mutate(document)
    path.write_text(json.dumps(document))
    with pytest.raises(FileFormatError):
        load_terrain_graph(path)


def test_navigation_respects_terrain_choice(build) -> None:
    scene = build.scene
    start = nearest_place(scene, [2.0, 1.5, 0.0], ["sidewalk"])
    goal = nearest_place(scene, [55.0, 1.5, 0.0], ["sidewalk"])
    route, length = shortest_route(scene, start, goal, ["sidewalk"])
    assert route[0] == start and route[-1] == goal
    assert all(scene.graph.nodes[n]["terrain"] == "sidewalk" for n in route)
    assert length >= 40.0
    grass = nearest_place(scene, [30.0, 15.0, 0.0], ["grass"])
    with pytest.raises(PlanningError, match="may not use"):
        shortest_route(scene, start, grass, ["sidewalk"])
    across, _ = shortest_route(scene, start, grass, ["sidewalk", "grass"])
    assert {scene.graph.nodes[n]["terrain"] for n in across} == {"sidewalk", "grass"}
    with pytest.raises(InvalidInputError):
        shortest_route(scene, "map", grass)


def test_impossible_parameters() -> None:
    with pytest.raises(InvalidInputError, match="cell_size"):
        make_terrain_params({"cell_size": 0})
    with pytest.raises(InvalidInputError, match="object_voxel"):
        make_terrain_params({"object_voxel": 2.0, "object_eps": 1.0})


def test_places_are_scored_against_true_patches(build) -> None:
    scene = build.scene
    sidewalk = shapely.box(0.0, 0.0, 60.0, 3.0)  # the scene's sidewalk strip
    mine = [n for n in scene.nodes_of("place") if scene.graph.nodes[n]["terrain"] == "sidewalk"]
    good = score_places(scene, "sidewalk", [sidewalk, shapely.box(0.0, 40.0, 2.0, 42.0)])
    # the 4 m^2 patch is below the minimum area and not scored
    assert (good.patches, good.with_places, good.connected) == (1, 1, 1)
    assert (good.places, good.off_terrain, good.all_connected) == (len(mine), 0, True)
    elsewhere = score_places(scene, "sidewalk", [shapely.box(0.0, 10.0, 60.0, 13.0)])
    assert (elsewhere.with_places, elsewhere.off_terrain) == (0, len(mine))
    assert elsewhere.worst_offset > 6.0
    cut = copy.deepcopy(scene)
    a, b = next(
        (a, b) for a, b, kind in cut.graph.subgraph(mine).edges(data="kind") if kind == "gvd"
    )
    cut.graph.remove_edge(a, b)
    assert score_places(cut, "sidewalk", [sidewalk]).connected == 0
    absent = score_places(scene, "sidewalk", [])
    assert absent.patches == 0 and absent.off_terrain == len(mine)
    assert absent.to_json()["worst_offset"] is None  # infinite: no such terrain at all
