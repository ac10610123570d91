import json

import numpy as np
import pytest

from cli_runner import run


def test_graph_command_end_to_end_on_a_small_cloud(
    capsys, tmp_path, labelled_scene, fake_encoder
) -> None:
    points, labels, names = labelled_scene
    cloud = tmp_path / "scene.npz"
    np.savez(cloud, points=points, labels=labels)
    out = tmp_path / "out"
    spec = ",".join(f"{k}={v}" for k, v in names.items())
    code, _, err = run(
        capsys, "terrain", "graph", str(cloud), "--out", str(out), "--encoder", "hashing-test",
        "--label-names", spec, "--param", "split_length=6.0",
    )  # fmt: skip
    assert code == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["objects"] == {"image of a tree": 2, "image of a car": 3}
    assert all(n > 0 for n in summary["places"].values())
    for name in ("graph.json", "graph.graphml", "layer1.npz", "classified_cloud.png",
                 "places.png", "layers.png", "gvd_0_sidewalk.png", "report.html"):  # fmt: skip
        assert (out / name).stat().st_size > 0, name
    graph = json.loads((out / "graph.json").read_text())
    places = [n["id"] for n in graph["nodes"] if n["kind"] == "place"]
    code, out_text, _ = run(
        capsys, "terrain", "route", str(out / "graph.json"), "--from", places[0], "--to", places[0]
    )
    assert code == 0 and "1 places" in out_text


def test_map_then_graph_evaluates_against_the_simulated_world(
    capsys, tmp_path, fake_encoder
) -> None:
    cloud = tmp_path / "cloud.npz"
    code, out_text, err = run(
        capsys, "terrain", "map", "--world", "outdoor", "-s", "small", "--seed", "0",
        "--encoder", "hashing-test", "--spacing", "3", "--out", str(cloud),
    )  # fmt: skip
    assert code == 0, err
    assert "29 frames" in out_text and cloud.stat().st_size > 0
    out = tmp_path / "graph"
    code, _, err = run(
        capsys, "terrain", "graph", str(cloud), "--encoder", "hashing-test",
        "--terrain-threshold", "0.3", "--terrain", "sidewalk,grass,asphalt", "--objects",
        "image of a tree,image of a car", "--evaluate", "--out", str(out),
    )  # fmt: skip
    assert code == 0, err
    quality = json.loads((out / "summary.json").read_text())["quality"]
    cars = quality["objects"]["image of a car"]
    assert (cars["ground_truth"], cars["precision"], cars["recall"]) == (2, 1.0, 1.0)
    assert all(p["all_connected"] and p["off_terrain"] == 0 for p in quality["places"].values())
    assert (out / "gvd_2_asphalt.png").stat().st_size > 0


def test_errors_are_one_line_and_exit_non_zero(
    tmp_path, capsys, labelled_scene, fake_encoder
) -> None:
    broken = tmp_path / "broken.pcd"
    broken.write_bytes(b"VERSION 0.7\nFIELDS x y z\n")
    points, labels, _ = labelled_scene
    plain = tmp_path / "plain.npz"
    np.savez(plain, points=points, labels=labels)
    cloud = str(tmp_path / "c.npz")
    for argv in (
        ["terrain", "graph", str(broken), "--out", str(tmp_path / "o")],
        ["terrain", "graph", str(broken), "--out", str(tmp_path / "o"), "--encoder", "nope"],
        ["terrain", "graph", str(broken), "--out", str(tmp_path / "o"), "--param", "cell_size=0"],
        ["terrain", "graph", str(plain), "--out", str(tmp_path / "o"), "--label-names",
         "0=sidewalk,1=grass,2=road,3=car,4=tree", "--encoder", "hashing-test", "--evaluate"],
        ["terrain", "map", "--world", "outdor", "--out", cloud],
        ["terrain", "map", "--world", "city", "-s", "small", "--out", cloud],
        ["terrain", "map", "-s", "small", "--spacing", "0", "--out", cloud],
    ):  # fmt: skip
        code, _, err = run(capsys, *argv)
        assert code == 1 and err.startswith("error:") and "\n" not in err.strip(), err


def test_a_bag_becomes_a_cloud_and_then_a_graph(capsys, tmp_path, labelled_scene, fake_encoder):
    pytest.importorskip("rosbags", reason="the 'ros' extra (rosbags) is not installed")
    from seminspect.mapping.formats.rosbag import BagScan
    from seminspect.mapping.formats.rosbag_writer import BagTopics, write_bag
    from seminspect.mapping.semantic_cloud import load_cloud

    points, labels, names = labelled_scene
    halves = [slice(0, len(points) // 2), slice(len(points) // 2, None)]
    scans = [BagScan(k * 10**8, points[h], labels[h], np.eye(4)) for k, h in enumerate(halves)]
    bag = write_bag(tmp_path / "drive", scans, names, BagTopics(cloud="/velodyne"))
    cloud = tmp_path / "cloud.npz"
    code, out_text, err = run(
        capsys, "terrain", "map", "--bag", str(bag), "--cloud-topic", "/velodyne",
        "--encoder", "hashing-test", "--noise", "0", "--out", str(cloud),
    )  # fmt: skip
    assert code == 0, err
    fused = load_cloud(cloud)
    assert f"{len(fused):,} points" in out_text and 0.99 * len(points) < len(fused) <= len(points)
    assert fused.source == {"bag": str(bag), "cloud_topic": "/velodyne", "odom_topic": "/odom"}
    out = tmp_path / "graph"
    code, _, err = run(
        capsys, "terrain", "graph", str(cloud), "--encoder", "hashing-test", "--terrain",
        "sidewalk,grass,road", "--param", "split_length=6.0", "--out", str(out),
    )  # fmt: skip
    assert code == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["objects"] == {"image of a tree": 2, "image of a car": 3}
    code, _, err = run(
        capsys, "terrain", "map", "--bag", str(bag), "--encoder", "hashing-test", "--out",
        str(tmp_path / "other.npz"),
    )  # fmt: skip
    assert code == 1 and "no topic '/points'" in err and len(err.strip().splitlines()) == 1


def test_kitti_prompts_are_scored_against_the_class_they_name(
    capsys, tmp_path, shared_data, fake_encoder
) -> None:
    root = shared_data / "semantickitti/seq00_frames000-002"
    out = tmp_path / "kitti"
    code, _, err = run(
        capsys, "terrain", "graph", str(root / "velodyne/000000.bin"), "--labels",
        str(root / "labels/000000.label"), "--encoder", "hashing-test", "--terrain", "sidewalk",
        "--objects", "trunk,image of a car", "--evaluate", "--out", str(out),
    )  # fmt: skip
    assert code == 0, err
    quality = json.loads((out / "summary.json").read_text())["quality"]
    trunk, car = quality["trunk"], quality["image of a car"]
    assert (trunk["ground_truth_class"], trunk["class_chosen_by"]) == ("trunk", "name")
    assert "no instances of 'trunk'" in trunk["unscored"] and "precision" not in trunk
    assert (car["ground_truth_class"], car["class_chosen_by"]) == ("car", "name")
    assert car["ground_truth"] > 5 and 0 < car["class_similarity"] <= 1.0


def _plane_with_two_boxes(seed: int = 0) -> np.ndarray:
    """A bare cloud: a 20 x 12 m plane at 0.15 m spacing with a car-sized and a 2 m box on it."""
    rng = np.random.default_rng(seed)
    xs, ys = np.meshgrid(np.arange(0, 20, 0.15), np.arange(0, 12, 0.15), indexing="ij")
    ground = np.column_stack([xs.ravel(), ys.ravel(), rng.normal(0, 0.01, xs.size)])
    parts = [ground]
    for low, size in (((3.0, 3.0), (4.5, 1.8, 1.5)), ((12.0, 6.0), (2.0, 2.0, 2.5))):
        n = int(2 * (size[0] + size[1]) * size[2] / 0.15**2 + size[0] * size[1] / 0.15**2)
        box = np.array([*low, 0.0]) + rng.uniform(0, 1, (n, 3)) * size
        side = rng.integers(0, 5, n)  # 0: top, 1-4: the sides
        box[side == 0, 2] = size[2]
        box[side == 1, 0], box[side == 2, 0] = low[0], low[0] + size[0]
        box[side == 3, 1], box[side == 4, 1] = low[1], low[1] + size[1]
        parts.append(box)
    return np.vstack(parts)


def test_a_bare_ply_takes_the_geometric_path_to_ground_and_two_objects(
    capsys, tmp_path, fake_encoder
) -> None:
    import trimesh

    cloud = tmp_path / "bare.ply"
    trimesh.PointCloud(_plane_with_two_boxes()).export(cloud)  # binary PLY, x y z only
    out = tmp_path / "out"
    code, text, err = run(
        capsys, "terrain", "graph", str(cloud), "--out", str(out), "--encoder", "hashing-test"
    )
    assert code == 0, err
    assert "geometric path" in text and str(cloud) in text
    summary = json.loads((out / "summary.json").read_text())
    assert summary["objects"] == {"object": 2}
    assert summary["places"]["ground"] > 0 and summary["regions"] > 0
    assert summary["geometric_path"]["points"]["ground"] > 9000
    assert summary["frame"]["origin_m"] == [0.0, 0.0, 0.0]


def _survey_las(path, units_code: int) -> np.ndarray:
    """The bare cloud in feet about a state-plane-like offset, with ASPRS classes."""
    import laspy
    from laspy.vlrs.known import GeoKeyDirectoryVlr, GeoKeyEntryStruct

    metres = _plane_with_two_boxes(seed=1)
    feet = metres / 0.3048 + np.array([1_312_000.0, 850_000.0, 400.0])
    header = laspy.LasHeader(point_format=3, version="1.2")
    header.offsets, header.scales = [1_312_000.0, 850_000.0, 0.0], [0.001, 0.001, 0.001]
    keys = GeoKeyDirectoryVlr()
    keys.geo_keys_header = GeoKeyEntryStruct(1, 1, 0, 1)
    keys.geo_keys = [GeoKeyEntryStruct(3076, 0, 1, units_code)]
    header.vlrs.append(keys)
    las = laspy.LasData(header)
    las.x, las.y, las.z = feet[:, 0], feet[:, 1], feet[:, 2]
    las.classification = np.where(metres[:, 2] < 0.1, 2, 1).astype(np.uint8)
    las.write(path)
    return feet


def test_a_laz_in_feet_is_read_in_metres_about_a_recorded_origin(
    capsys, tmp_path, fake_encoder
) -> None:
    laz = tmp_path / "survey.laz"
    feet = _survey_las(laz, 9002)
    out = tmp_path / "out"
    code, text, err = run(
        capsys, "terrain", "graph", str(laz), "--out", str(out), "--encoder", "hashing-test"
    )
    assert code == 0, err
    assert "international feet (from the file's header, GeoTIFF key 3076)" in text
    summary = json.loads((out / "summary.json").read_text())
    frame = summary["frame"]
    assert frame["units"] == "ft" and frame["metres_per_unit"] == [0.3048] * 3
    assert frame["origin_m"] == np.floor(feet.min(axis=0) * 0.3048).tolist()
    assert summary["objects"] == {"object": 2}
    truth = summary["geometric_path"]["errors_against_class_2"]
    assert truth["type_1"] < 0.01
    graph = json.loads((out / "graph.json").read_text())
    boxes = [n for n in graph["nodes"] if n["kind"] == "object"]
    extents = sorted(max(np.subtract(n["bbox_max"], n["bbox_min"])[:2]) for n in boxes)
    np.testing.assert_allclose(extents, [2.0, 4.5], atol=0.3)  # metres, not feet

    code, text, err = run(
        capsys, "terrain", "graph", str(laz), "--out", str(out), "--encoder", "hashing-test",
        "--units", "m",
    )  # fmt: skip
    assert code == 0, err
    assert json.loads((out / "summary.json").read_text())["frame"]["units_from"] == "from --units"


def test_las_classes_become_labels_only_when_asked(capsys, tmp_path, fake_encoder) -> None:
    las = tmp_path / "survey.las"
    _survey_las(las, 9002)
    out = tmp_path / "out"
    code, text, err = run(
        capsys, "terrain", "graph", str(las), "--out", str(out), "--encoder", "hashing-test",
        "--labels-from", "classification", "--terrain", "ground", "--objects", "building",
    )  # fmt: skip
    assert code == 0, err
    assert "geometric path" not in text
    summary = json.loads((out / "summary.json").read_text())
    assert "geometric_path" not in summary and summary["layer1_points"]["ground"] > 9000


def test_point_file_errors_name_the_file(capsys, tmp_path, fake_encoder) -> None:
    import trimesh

    ply = tmp_path / "bare.ply"
    trimesh.PointCloud(_plane_with_two_boxes()).export(ply)
    broken = tmp_path / "broken.laz"
    broken.write_bytes(b"LASF" + bytes(60))
    lonely = tmp_path / "lonely.ply"
    trimesh.PointCloud(np.zeros((1, 3))).export(lonely)
    out = str(tmp_path / "o")
    for argv, named in (
        (["terrain", "graph", str(broken), "--out", out], broken),
        (["terrain", "graph", str(ply), "--out", out, "--labels-from", "classification"], ply),
        (["terrain", "graph", str(lonely), "--out", out, "--encoder", "hashing-test"], lonely),
    ):
        code, _, err = run(capsys, *argv)
        assert code == 1 and err.startswith("error:") and "\n" not in err.strip(), err
        assert str(named) in err, err
    code, _, err = run(capsys, "terrain", "graph", str(ply), "--out", out, "--units", "yard")
    assert code == 1 and "--units must be one of m, ft, us-ft" in err


def test_autzen_laz_builds_a_graph_its_ground_class_confirms(
    capsys, tmp_path, shared_data, fake_encoder
) -> None:
    out = tmp_path / "autzen"
    laz = shared_data / "aerial_lidar_las" / "autzen_trim.laz"
    code, _, err = run(
        capsys, "terrain", "graph", str(laz), "--out", str(out), "--encoder", "hashing-test"
    )
    assert code == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["frame"]["units"] == "ft"
    assert summary["geometric_path"]["errors_against_class_2"]["type_1"] < 0.01
    assert summary["objects"]["object"] > 10
    assert summary["regions"] < summary["places"]["ground"] / 3
