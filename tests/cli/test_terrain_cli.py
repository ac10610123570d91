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
    from seminspect.mapping.formats.rosbag import BagScan, BagTopics, write_bag
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
