"""The learned detector at run time: the smoke training's export run by onnxruntime on frames
it never saw, the Detection fields, the seams, the evaluation, and every refusal in one line."""

from __future__ import annotations

import numpy as np
import pytest
from onnx import TensorProto, helper, save

from detector_data import draw_frame, smoke_training, write_dataset
from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.perception.evaluation import dataset_frame, evaluate_detector
from seminspect.perception.learned import LearnedDetector, _split_at_seams
from seminspect.perception.training_data import seams
from seminspect.sensors import Detector
from seminspect.sensors.detector import reads_image

pytest.importorskip("torch")


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    from seminspect.perception.training import export_onnx

    _, result = smoke_training(tmp_path_factory.getbasetemp())
    return export_onnx(result.checkpoint, tmp_path_factory.mktemp("model") / "model.onnx")


@pytest.fixture(scope="module")
def detector(model) -> LearnedDetector:
    return LearnedDetector.load(model, threads=1)


def _single_car(seed: int = 12):
    rng = np.random.default_rng(seed)
    drawn = draw_frame(rng, 1)
    return dataset_frame(drawn["rgb"], drawn["depth"]), drawn


def _iou(a: np.ndarray, b: np.ndarray) -> float:
    return float((a & b).sum() / (a | b).sum())


def test_it_finds_an_unseen_car_with_every_field_right(detector) -> None:
    seen: Detector = detector
    assert seen.name == "learned:model.onnx" and reads_image(detector)
    frame, truth = _single_car()
    found = detector.detect(frame, "instance", ["car", "truck", "building"])
    cars = [d for d in found if d.label == "car"]
    assert len(cars) == 1
    car = cars[0]
    assert _iou(car.mask, truth["instance"] == 1) > 0.7
    rows, cols = np.nonzero(car.mask)
    assert car.bbox == (cols.min(), rows.min(), cols.max() + 1, rows.max() + 1)
    assert car.area_px == car.mask.sum() and car.mask.shape == frame.shape
    assert 0.5 < car.score <= 1 and car.instance_id == -1 and car.level == "instance"
    assert car.depth_m == pytest.approx(float(np.median(frame.depth[car.mask])))
    assert detector.detect(frame, "instance", ["truck"]) == []


def test_cars_of_any_paint_are_found(detector) -> None:
    ious = []
    for seed in range(10, 20):  # some as pale as their windows, some as dark as their wheels
        frame, truth = _single_car(seed)
        cars = detector.detect(frame, "instance", ["car"])
        ious.append(max((_iou(c.mask, truth["instance"] == 1) for c in cars), default=0.0))
    assert min(ious) > 0.5 and np.mean(ious) > 0.75


def test_parts_lie_on_their_object(detector) -> None:
    frame, truth = _single_car()
    car = detector.detect(frame, "instance", ["car"])[0]
    parts = detector.detect(frame, "part", ["wheel", "window"])
    assert {p.label for p in parts} >= {"window"}
    for part in parts:
        assert part.level == "part" and not (part.mask & ~car.mask).any()
    windows = np.logical_or.reduce([p.mask for p in parts if p.label == "window"])
    assert _iou(windows, truth["part_id"] == 2) > 0.3


def test_a_frame_of_another_size_and_a_grey_frame_are_read(detector) -> None:
    frame, truth = _single_car()
    big = dataset_frame(
        np.repeat(np.repeat(frame.rgb, 2, axis=0), 2, axis=1),
        np.repeat(np.repeat(truth["depth"], 2, axis=0), 2, axis=1),
    )
    cars = detector.detect(big, "instance", ["car"])
    assert cars and cars[0].mask.shape == (96, 128)
    wanted = np.repeat(np.repeat(truth["instance"] == 1, 2, axis=0), 2, axis=1)
    assert _iou(cars[0].mask, wanted) > 0.6
    grey = dataset_frame(frame.rgb, truth["depth"])
    grey.intensity, grey.rgb = frame.rgb.mean(axis=2).astype(np.uint8), None
    assert isinstance(detector.detect(grey, "instance", ["car"]), list)


def test_two_touching_cars_are_two_detections(detector) -> None:
    rng = np.random.default_rng(21)
    drawn = draw_frame(rng, 2)
    while not seams(drawn["instance"][None]).any():
        drawn = draw_frame(rng, 2)
    frame = dataset_frame(drawn["rgb"], drawn["depth"])
    cars = detector.detect(frame, "instance", ["car"])
    assert len(cars) == 2
    for car in cars:
        best = max(_iou(car.mask, drawn["instance"] == k) for k in (1, 2))
        assert best > 0.7


def test_seams_split_two_touching_objects() -> None:
    mask = np.zeros((10, 20), bool)
    mask[2:8, 2:18] = True
    seam = np.zeros_like(mask)
    seam[:, 9:11] = True
    components = _split_at_seams(mask, seam)
    assert set(np.unique(components[mask])) == {1, 2}
    assert (components[2:8, 2:10] == components[2, 2]).all()
    assert (components[~mask] == 0).all()


def test_the_evaluation_measures_unseen_frames(detector, tmp_path) -> None:
    data = write_dataset(tmp_path / "held-out", frames=6, shard_size=3, seed=5)
    result = evaluate_detector(detector, data)
    summary = result.summary()
    assert summary["frames"] == 6
    assert summary["vehicle_iou"] > 0.6
    assert summary["recall"] > 0.5 and summary["precision"] > 0.5
    assert set(summary["part_iou"]) <= {"wheel", "window"}
    assert summary["cpu_ms_per_frame"] > 0
    assert evaluate_detector(detector, data, limit=2).frames == 2


def _one_line(excinfo) -> str:
    message = str(excinfo.value)
    assert "\n" not in message
    return message


def test_a_missing_or_foreign_model_is_one_line(tmp_path) -> None:
    with pytest.raises(FileFormatError, match="no such model file") as caught:
        LearnedDetector.load(tmp_path / "none.onnx")
    _one_line(caught)
    images = helper.make_tensor_value_info("images", TensorProto.FLOAT, [1, 3, 8, 8])
    out = helper.make_tensor_value_info("out", TensorProto.FLOAT, [1, 3, 8, 8])
    graph = helper.make_graph([helper.make_node("Relu", ["images"], ["out"])], "g", [images], [out])
    save(helper.make_model(graph, opset_imports=[helper.make_opsetid("", 17)]), tmp_path / "x.onnx")
    with pytest.raises(FileFormatError, match="not a seminspect learned-detector model") as caught:
        LearnedDetector.load(tmp_path / "x.onnx")
    _one_line(caught)
    (tmp_path / "junk.onnx").write_bytes(b"not onnx")
    with pytest.raises(FileFormatError, match="not an ONNX model") as caught:
        LearnedDetector.load(tmp_path / "junk.onnx")
    _one_line(caught)


def test_a_frame_it_cannot_read_is_one_line(detector) -> None:
    frame, truth = _single_car()
    frame.depth[0, 0] = np.nan
    with pytest.raises(InvalidInputError, match="NaN") as caught:
        detector.detect(frame, "instance", ["car"])
    _one_line(caught)
    blind = dataset_frame(frame.rgb, truth["depth"])
    blind.rgb = None
    with pytest.raises(InvalidInputError, match="no image") as caught:
        detector.detect(blind, "part", ["wheel"])
    _one_line(caught)
    with pytest.raises(InvalidInputError, match="min_area_px"):
        LearnedDetector.load("unused.onnx", min_area_px=0)
