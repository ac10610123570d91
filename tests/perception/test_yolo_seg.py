"""A YOLOv8-seg model in ONNX as a Detector: tiny models built here with onnx.helper whose
outputs are fixed (plus zero times the input), so every box, mask and score is known."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from onnx import TensorProto, helper, numpy_helper, save

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.perception import ClassMap, YoloSegDetector
from seminspect.perception.yolo_seg import frame_image, letterbox, nms
from seminspect.sensors import CameraModel, Detector, Frame

INPUT = (64, 64)  # the model's (H, W); prototypes are 16 x 16
FRAME = (96, 128)  # the frame's (h, w): scaled by 0.5 into 64 x 48, 8 rows of grey above
CLASSES = {"instance": {"0": "car", "1": "truck"}, "part": {"2": "hood"}}
# Regions in model-input pixels [x0, x1) x [y0, y1), on whole prototype cells (4 px).
CAR_REGION = (16, 48, 16, 40)  # in the frame: x 32-96, y 16-64
HOOD_REGION = (8, 24, 44, 52)  # in the frame: x 16-48, y 72-88


def _frame_box(region: tuple[int, int, int, int]) -> tuple[int, int, int, int]:
    """A model-input region in frame pixels ``(x0, y0, x1, y1)``: the letterbox undone."""
    x0, x1, y0, y1 = region
    return x0 * 2, (y0 - 8) * 2, x1 * 2, (y1 - 8) * 2


def _candidate(cls: int, score: float, region, coefficients, shift: float = 0.0) -> np.ndarray:
    x0, x1, y0, y1 = region
    box = [(x0 + x1) / 2 + shift, (y0 + y1) / 2, x1 - x0, y1 - y0]
    scores = np.zeros(3)
    scores[cls] = score
    return np.concatenate([box, scores, coefficients])


def _prototype(region) -> np.ndarray:
    x0, x1, y0, y1 = (v // 4 for v in region)
    proto = np.full((16, 16), -8.0)
    proto[y0:y1, x0:x1] = 8.0
    return proto


SCENE = np.stack(
    [
        _candidate(0, 0.9, CAR_REGION, [1, 0]),
        _candidate(0, 0.8, CAR_REGION, [1, 0], shift=2.0),  # IoU 0.88 with the first: suppressed
        _candidate(2, 0.7, HOOD_REGION, [0, 1]),
        _candidate(0, 0.1, HOOD_REGION, [0, 1]),  # below the default score threshold
        _candidate(1, 0.6, CAR_REGION, [1, 0]),  # another class: NMS is class-wise
        np.zeros(9),  # background: no class scores
    ],
    axis=1,
)
PROTOS = np.stack([_prototype(CAR_REGION), _prototype(HOOD_REGION)])


def write_model(
    path: Path,
    candidates: np.ndarray = SCENE,
    protos: np.ndarray = PROTOS,
    *,
    input_shape: tuple[int, ...] = (1, 3, *INPUT),
    outputs: tuple[str, ...] = ("output0", "output1"),
) -> Path:
    """A model whose outputs are ``candidates`` and ``protos`` plus 0 x the sum of its input."""
    zero = numpy_helper.from_array(np.array(0, np.float32), "zero")
    fixed = [
        numpy_helper.from_array(a[None].astype(np.float32), f"fixed{i}")
        for i, a in enumerate((candidates, protos))
    ]
    nodes = [
        helper.make_node("Mul", ["images", "zero"], ["nothing"]),
        helper.make_node("ReduceSum", ["nothing"], ["none"], keepdims=0),
    ] + [helper.make_node("Add", [f"fixed{i}", "none"], [name]) for i, name in enumerate(outputs)]
    shapes = [[1, *candidates.shape], [1, *protos.shape]]
    graph = helper.make_graph(
        nodes,
        "tiny-yolov8-seg",
        [helper.make_tensor_value_info("images", TensorProto.FLOAT, list(input_shape))],
        [
            helper.make_tensor_value_info(n, TensorProto.FLOAT, s)
            for n, s in zip(outputs, shapes, strict=False)
        ],
        initializer=[zero, *fixed],
    )
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 17)])
    model.ir_version = 8
    save(model, str(path))
    return path


def write_class_map(path: Path, data=CLASSES) -> Path:
    path.write_text(json.dumps(data))
    return path


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> tuple[Path, Path]:
    folder = tmp_path_factory.mktemp("model")
    return write_model(folder / "tiny.onnx"), write_class_map(folder / "classes.json")


@pytest.fixture(scope="module")
def detector(files) -> YoloSegDetector:
    return YoloSegDetector.load(*files, threads=1)


def make_frame(shape=FRAME, depth: np.ndarray | None = None, intensity=True) -> Frame:
    height, width = shape
    if depth is None:
        depth = np.full(shape, 9.0, np.float32)
        x0, y0, x1, y1 = _frame_box(CAR_REGION)
        depth[y0:y1, x0:x1] = 3.0
        depth[y0:y1, x0 : x0 + 8] = np.inf  # nothing seen there: not in the median
        x0, y0, x1, y1 = _frame_box(HOOD_REGION)
        depth[y0:y1, x0:x1] = 5.0
    zeros = np.zeros(shape, np.int32)
    grey = np.full(shape, 100, np.uint8) if intensity else None
    return Frame(
        depth.astype(np.float32),
        zeros,
        zeros.astype(np.int16),
        zeros.astype(np.int16),
        grey,
        zeros - 1,
        np.zeros(3),
        np.array([0.0, 0.0, 0.0, 1.0]),
        0.0,
        CameraModel(width=width, height=height),
    )


def _iou(mask: np.ndarray, box: tuple[int, int, int, int]) -> float:
    expected = np.zeros_like(mask)
    x0, y0, x1, y1 = box
    expected[y0:y1, x0:x1] = True
    return (mask & expected).sum() / (mask | expected).sum()


def test_the_detector_finds_the_models_car_where_the_letterbox_put_it(detector) -> None:
    seam: Detector = detector  # what a mission takes
    assert seam.name == "onnx:tiny.onnx"
    (car,) = detector.detect(make_frame(), "instance", ["car"])
    assert (car.label, car.level, car.instance_id) == ("car", "instance", -1)
    assert car.score == pytest.approx(0.9)
    assert car.bbox == _frame_box(CAR_REGION)
    assert _iou(car.mask, car.bbox) > 0.99 and car.area_px == car.mask.sum()
    assert car.mask.shape == FRAME and car.depth_m == 3.0  # the median of the finite depths


def test_nms_is_class_wise_and_the_labels_and_level_filter(detector) -> None:
    frame = make_frame()
    found = detector.detect(frame, "instance", ["car", "truck"])
    assert [(d.label, round(d.score, 2)) for d in found] == [("car", 0.9), ("truck", 0.6)]
    (hood,) = detector.detect(frame, "part", ["hood", "car"])
    assert (hood.label, hood.level, hood.bbox) == ("hood", "part", _frame_box(HOOD_REGION))
    assert hood.depth_m == 5.0 and _iou(hood.mask, hood.bbox) > 0.95  # corners upsampled round
    assert detector.detect(frame, "part", ["car"]) == []
    assert detector.detect(frame, "instance", ["hood", "bus"]) == []


def test_a_lower_score_threshold_lets_the_weak_candidate_through(files) -> None:
    lenient = YoloSegDetector.load(*files, score_threshold=0.05, threads=1)
    found = lenient.detect(make_frame(), "instance", ["car"])
    assert [d.bbox for d in found] == [_frame_box(CAR_REGION), _frame_box(HOOD_REGION)]


def test_a_frame_the_size_of_the_input_needs_no_letterbox(detector) -> None:
    (car,) = detector.detect(make_frame(shape=INPUT), "instance", ["car"])
    x0, x1, y0, y1 = CAR_REGION
    assert car.bbox == (x0, y0, x1, y1) and car.depth_m == 9.0


def test_the_input_is_the_letterboxed_image_grey_or_rgb() -> None:
    frame = make_frame(shape=(48, 32))  # portrait: scaled by 4/3, grey columns either side
    tensor, fit = letterbox(frame_image(frame), INPUT)
    assert tensor.shape == (1, 3, 64, 64) and tensor.dtype == np.float32
    assert (fit.scale_x, fit.scale_y, fit.left, fit.top) == (43 / 32, 64 / 48, 10, 0)
    assert np.allclose(tensor[0, :, :, 10:53], 100 / 255)
    assert np.allclose(tensor[0, :, :, :10], 114 / 255) and np.allclose(
        tensor[0, :, :, 53:], 114 / 255
    )
    frame.rgb = np.zeros((48, 32, 3), np.uint8)
    frame.rgb[..., 0] = 255
    image = frame_image(frame)
    assert image[..., 0].min() == 1.0 and image[..., 1:].max() == 0.0
    frame.rgb = np.zeros((48, 31, 3), np.uint8)
    with pytest.raises(InvalidInputError, match=r"expected \(48, 32\) grey or \(48, 32, 3\) RGB"):
        frame_image(frame)


def test_nms_keeps_the_best_of_overlapping_boxes() -> None:
    boxes = np.array([[0, 0, 10, 10], [1, 0, 11, 10], [20, 20, 30, 30]], dtype=float)
    assert nms(boxes, np.array([0.5, 0.9, 0.4]), 0.5) == [1, 2]


def _one_line(excinfo) -> str:
    message = str(excinfo.value)
    assert "\n" not in message
    return message


def test_a_model_file_that_is_missing_or_not_onnx_is_refused(tmp_path, files) -> None:
    classes = files[1]
    with pytest.raises(FileFormatError, match="no such model file") as excinfo:
        YoloSegDetector.load(tmp_path / "absent.onnx", classes)
    _one_line(excinfo)
    (tmp_path / "junk.onnx").write_bytes(b"not a model at all")
    with pytest.raises(FileFormatError, match="not an ONNX model onnxruntime can run") as excinfo:
        YoloSegDetector.load(tmp_path / "junk.onnx", classes)
    _one_line(excinfo)


def test_a_model_of_another_layout_says_what_was_expected_and_found(tmp_path, files) -> None:
    classes = files[1]
    grey = write_model(tmp_path / "grey.onnx", input_shape=(1, 1, *INPUT))
    with pytest.raises(FileFormatError, match="expected one input 'images'") as excinfo:
        YoloSegDetector.load(grey, classes)
    assert "found images tensor(float) [1, 1, 64, 64]" in _one_line(excinfo)
    boxes_only = write_model(tmp_path / "det.onnx", outputs=("output0",))
    with pytest.raises(FileFormatError, match="expected YOLOv8-seg outputs") as excinfo:
        YoloSegDetector.load(boxes_only, classes)
    assert "found output0 tensor(float) [1, 9, 6]" in _one_line(excinfo)
    renamed = write_model(tmp_path / "renamed.onnx", outputs=("boxes", "masks"))
    assert YoloSegDetector.load(renamed, classes).layout.candidates == "boxes"


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"instance": {"0": "car", "1": "truck"}}, "neither maps nor ignores 2"),
        ({**CLASSES, "ignore": [5]}, r"names classes 5 but the model has 3 \(0-2\)"),
        ({**CLASSES, "part": {"2": "car"}}, r"\['car'\] are both instance and part labels"),
        ({**CLASSES, "part": {"x": "hood"}}, "'part' key 'x' is not a class id"),
        ({**CLASSES, "ignore": [2]}, r"classes \[2\] are both mapped and ignored"),
        ({**CLASSES, "parts": {}}, "expected an object with 'instance', 'part' and 'ignore'"),
        ({"instance": {"0": "car", "1": ""}, "part": {"2": "hood"}}, "class 1 has no label"),
    ],
)
def test_a_class_map_that_does_not_fit_the_model_is_refused(tmp_path, files, data, message):
    path = write_class_map(tmp_path / "classes.json", data)
    with pytest.raises(FileFormatError, match=message) as excinfo:
        YoloSegDetector.load(files[0], path)
    _one_line(excinfo)


def test_ignored_classes_are_never_reported(files) -> None:
    classes = ClassMap.parse({"instance": {0: "car", 1: "truck"}, "ignore": [2]})
    detector = YoloSegDetector.load(files[0], classes, threads=1)
    assert detector.detect(make_frame(), "part", ["hood"]) == []
    assert len(detector.detect(make_frame(), "instance", ["car"])) == 1


def test_bad_frames_and_thresholds_are_refused_in_one_line(files, detector) -> None:
    depth = np.full(FRAME, 4.0, np.float32)
    depth[3, 4] = np.nan
    with pytest.raises(InvalidInputError, match="depth holds NaN") as excinfo:
        detector.detect(make_frame(depth=depth), "instance", ["car"])
    _one_line(excinfo)
    with pytest.raises(InvalidInputError, match="without its intensity image"):
        detector.detect(make_frame(intensity=False), "instance", ["car"])
    with pytest.raises(InvalidInputError, match=r"score threshold must lie in \(0, 1\), got 1.5"):
        YoloSegDetector.load(*files, score_threshold=1.5)


def test_a_mission_sees_through_the_model_and_records_its_name(tmp_path) -> None:
    from seminspect.core.io import read_versioned_json
    from seminspect.missions.xflie.config import make_config
    from seminspect.missions.xflie.run import run_mission

    blind = SCENE.copy()
    blind[4:7] = 0.0  # no class scores: the tiny model sees nothing in a real frame
    model = write_model(tmp_path / "blind.onnx", blind)
    detector = YoloSegDetector.load(model, write_class_map(tmp_path / "c.json"), threads=1)
    config = make_config({"world": "campus", "scenario": "small", "seed": 0, "time_budget_s": 60})
    result = run_mission(config, tmp_path / "run", detector=detector)
    assert result.state == "completed"
    seen = detector._last  # the last frame it was given, rendered with its image for it
    assert seen is not None and seen[0].intensity is not None
    metrics = read_versioned_json(tmp_path / "run" / "metrics.json", "seminspect.run-metrics", [1])
    assert metrics["world"]["detector"] == "onnx:blind.onnx"
