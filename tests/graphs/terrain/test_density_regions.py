"""Parameters from the terrain's point spacing, and regions that group places (issue 27)."""

import warnings

import numpy as np
import pytest

from seminspect.graphs.terrain.params import (
    DENSE_SPACING,
    TerrainGraphParams,
    make_terrain_params,
    params_for_cloud,
)
from seminspect.graphs.terrain.places import TerrainWarning, place_groups
from seminspect.graphs.terrain.prompting import TaskPrompts
from seminspect.graphs.terrain.regions import agglomerate, task_distributions
from seminspect.graphs.terrain.scene_graph import build_terrain_graph
from seminspect.mapping.formats.pointfiles import PointData
from seminspect.mapping.ingest import cloud_from_point_data

FIELDS = TaskPrompts.parse("grass,asphalt", "image of a car")


def grid(step: float, size: tuple[float, float] = (40.0, 30.0)) -> np.ndarray:
    xs, ys = np.meshgrid(np.arange(0, size[0], step), np.arange(0, size[1], step), indexing="ij")
    return np.column_stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)])


def airborne_fields(seed: int = 0) -> tuple[np.ndarray, np.ndarray, dict[int, str]]:
    """Two 120 m x 35 m grass fields either side of a 10 m road, sampled at random at airborne
    density (0.7 points per square metre: median spacing about 0.56 m), and three cars."""
    rng = np.random.default_rng(seed)
    ground = rng.uniform([0.0, 0.0, 0.0], [120.0, 80.0, 0.05], (6720, 3))
    road = np.abs(ground[:, 1] - 40.0) < 5.0
    cars = [rng.uniform([x, 36.5, 0.2], [x + 4.5, 38.3, 1.6], (60, 3)) for x in (20, 60, 95)]
    points = np.vstack([ground, *cars])
    labels = np.concatenate([np.where(road, 1, 0), np.full(180, 2)])
    return points, labels, {0: "grass", 1: "road", 2: "car"}


@pytest.fixture(scope="module")
def fields_cloud(fake_encoder):
    points, labels, names = airborne_fields()
    return cloud_from_point_data(PointData(points, labels=labels, label_names=names), fake_encoder)


def test_dense_clouds_keep_the_defaults() -> None:
    # the tests' labelled scene (0.3 m) and ground-robot LiDAR are denser than DENSE_SPACING
    choice = params_for_cloud(grid(0.3))
    assert choice.params == TerrainGraphParams() and choice.derived == {}
    assert choice.spacing == pytest.approx(0.3) and choice.spacing < DENSE_SPACING
    assert "default parameters" in choice.describe()


def test_sparse_clouds_get_a_grid_three_spacings_a_cell() -> None:
    choice = params_for_cloud(grid(0.6))
    params = choice.params
    assert params.cell_size == pytest.approx(1.8)
    scale = params.cell_size / TerrainGraphParams().cell_size
    assert params.min_patch_area == pytest.approx(4.0 * scale**2, rel=0.02)
    assert params.prune_length == pytest.approx(1.5 * scale, rel=0.02)
    assert params.object_eps == pytest.approx(1.5) and params.object_voxel < params.object_eps
    assert set(choice.derived) >= {"cell_size", "min_patch_area", "object_eps"}
    assert "cell_size 1.8" in choice.describe()


def test_what_the_user_sets_wins() -> None:
    mapping = params_for_cloud(grid(0.6), {"cell_size": 1.0, "object_eps": 0.9})
    assert mapping.params.cell_size == 1.0 and mapping.params.object_eps == 0.9
    assert "cell_size" not in mapping.derived and mapping.params.object_voxel < 0.9
    built = params_for_cloud(grid(0.6), make_terrain_params({"min_patch_area": 2.0}))
    assert built.params.min_patch_area == 2.0 and built.params.cell_size == pytest.approx(1.8)
    # a full parameter object of defaults counts as nothing chosen
    assert params_for_cloud(grid(0.6), TerrainGraphParams()).params.cell_size == 1.8


def test_one_task_everywhere_still_groups_linked_places() -> None:
    # every primitive serves the same task, so I(X;Y) = 0 and the budget is 0 (rounding made it
    # slightly negative before): linked places must still merge, up to the size bound
    similarity = np.tile([0.9, 0.1], (10, 1))
    py_x = task_distributions(similarity, null_similarity=0.2, top_k=2)
    chain = [(i, i + 1) for i in range(9)]
    positions = np.column_stack([np.arange(10) * 10.0, np.zeros(10)])
    assert len(set(agglomerate(py_x, chain, 0.02).assignment.tolist())) == 1
    bounded = agglomerate(py_x, chain, 0.02, positions, max_extent=25.0).assignment
    sizes = np.bincount(bounded)
    assert sizes.max() <= 3 and len(sizes) <= 5  # regions of 2-3 places, spread evenly
    for region in range(len(sizes)):
        members = positions[bounded == region, 0]
        assert np.ptp(members) <= 25.0


def test_airborne_fields_give_few_regions_of_one_terrain_each(fields_cloud, fake_encoder) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error", TerrainWarning)
        build = build_terrain_graph(fields_cloud, FIELDS, fake_encoder)
    assert build.choice is not None and build.choice.spacing > DENSE_SPACING
    assert build.scene.params.cell_size == build.choice.params.cell_size > 1.0
    graph, places = build.scene.graph, build.scene.nodes_of("place")
    regions = build.scene.nodes_of("region")
    assert place_groups(build.places) <= 3  # one place graph per field and one for the road
    assert len(places) >= 15 and len(regions) <= len(places) / 5
    for region in regions:
        members = [m for m in graph[region] if graph.nodes[m]["kind"] == "place"]
        assert len({graph.nodes[m]["terrain"] for m in members}) <= 1
        xy = np.array([graph.nodes[m]["position"][:2] for m in members]).reshape(-1, 2)
        if len(xy):
            assert np.hypot(*np.ptp(xy, axis=0)) <= build.scene.params.region_max_extent


def test_a_grid_too_fine_for_the_spacing_is_warned_with_a_cell_size(
    fields_cloud, fake_encoder
) -> None:
    params = make_terrain_params({"cell_size": 0.5})
    with pytest.warns(TerrainWarning, match=r"unlinked groups.*--cell-size 1\.\d"):
        build = build_terrain_graph(fields_cloud, FIELDS, fake_encoder, params=params)
    assert build.scene.params.cell_size == 0.5  # the user's cell is kept


def test_autzen_ground_class_gives_connected_places_and_grouping_regions(
    shared_data, fake_encoder
) -> None:
    data = np.load(shared_data / "aerial_lidar_las" / "autzen_trim_points.npz")
    points = data["xyz"] * 0.3048  # international feet
    points -= points.min(axis=0)
    labels = data["classification"].astype(np.int64)
    names = {1: "car", 2: "grass"}
    cloud = cloud_from_point_data(PointData(points, labels=labels, label_names=names), fake_encoder)
    build = build_terrain_graph(cloud, FIELDS, fake_encoder)
    assert build.choice is not None and 0.5 < build.choice.spacing < 0.7
    places, regions = build.scene.nodes_of("place"), build.scene.nodes_of("region")
    # at the old 0.5 m cells: 569 places in 268 unlinked groups, 569 regions
    assert len(places) > 300 and place_groups(build.places) <= 20
    assert len(regions) < len(places) / 3
