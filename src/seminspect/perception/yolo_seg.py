"""A detector of the user's own: an instance-segmentation model in ONNX with YOLOv8-seg's outputs.

000 Sec VI-B segments objects with YOLOv8-seg. A model trained on real images reaches seminspect
as an ONNX export with that model's layout, run here by onnxruntime on the CPU; seminspect never
imports the trainer. :class:`YoloSegDetector` is a :class:`~seminspect.sensors.Detector`:

- input: one float32 tensor ``(1, 3, H, W)``, RGB in [0, 1], the frame letterboxed into the
  model's fixed size as YOLOv8 does (scaled to fit, centred, grey 114 around it), so a frame of
  any size works. The frame's ``rgb`` image is used when it has one, else its grey
  ``intensity`` in all three channels.
- ``output0`` ``(1, 4 + nc + nm, N)``: per candidate the box (centre x, y, width, height in input
  pixels), ``nc`` class scores and ``nm`` mask coefficients; ``output1`` ``(1, nm, mh, mw)``: the
  mask prototypes.
- the class map (:class:`ClassMap`, a JSON file) names each model class as a seminspect label of
  one level, ``instance`` (a target class) or ``part``, or ignores it; a class the model can
  output that the map does not account for is refused when the detector is loaded.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import cv2
import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import read_json
from seminspect.sensors.camera import Frame
from seminspect.sensors.segmentation import Detection, Level

#: YOLOv8's letterbox grey, as a fraction of full scale.
PAD_VALUE = 114 / 255


@dataclass(frozen=True)
class ClassMap:
    """Model class id -> ``(label, level)``, and the ids the model may output that mean nothing
    here (a COCO model's ``person``, say), so that every class is accounted for."""

    classes: Mapping[int, tuple[str, Level]]
    ignored: frozenset[int] = frozenset()

    @classmethod
    def read(cls, path: str | os.PathLike[str]) -> ClassMap:
        """A class-map file, e.g. ``{"instance": {"0": "car"}, "part": {"1": "hood"},
        "ignore": [2]}``."""
        return cls.parse(read_json(path), str(path))

    @classmethod
    def parse(cls, data: Any, source: str = "class map") -> ClassMap:
        """The class map in ``data`` (the file's JSON, or the same shape with int keys)."""
        if not isinstance(data, dict) or set(data) - {"instance", "part", "ignore"}:
            found = sorted(data) if isinstance(data, dict) else type(data).__name__
            raise FileFormatError(
                f"{source}: expected an object with 'instance', 'part' and 'ignore', found {found}"
            )
        classes: dict[int, tuple[str, Level]] = {}
        for level in ("instance", "part"):
            for key, label in _entries(data.get(level, {}), source, level):
                if key in classes:
                    raise FileFormatError(f"{source}: class {key} is mapped twice")
                classes[key] = (label, level)
        levels = {label: level for label, level in classes.values()}
        both = sorted({label for label, level in classes.values() if levels[label] != level})
        if both:
            raise FileFormatError(f"{source}: {both} are both instance and part labels")
        ignored = data.get("ignore", [])
        if not isinstance(ignored, list) or not all(_is_id(i) for i in ignored):
            raise FileFormatError(
                f"{source}: 'ignore' must be a list of class ids, got {ignored!r}"
            )
        if twice := sorted(set(classes) & set(ignored)):
            raise FileFormatError(f"{source}: classes {twice} are both mapped and ignored")
        return cls(classes, frozenset(int(i) for i in ignored))

    def check(self, classes: int, source: str) -> None:
        """Refuse a map that leaves one of the model's ``classes`` unaccounted for, or names a
        class the model does not have (the map of another model)."""
        known = set(self.classes) | self.ignored
        if missing := sorted(set(range(classes)) - known):
            raise FileFormatError(
                f"{source}: the model outputs classes 0-{classes - 1} but the class map neither "
                f"maps nor ignores {_listed(missing)}"
            )
        if extra := sorted(known - set(range(classes))):
            raise FileFormatError(
                f"{source}: the class map names classes {_listed(extra)} but the model has "
                f"{classes} (0-{classes - 1})"
            )


def _is_id(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= 0


def _entries(table: Any, source: str, level: str) -> list[tuple[int, str]]:
    """``(class id, label)`` of one level's table, ids given as JSON strings or ints."""
    if not isinstance(table, dict):
        raise FileFormatError(f"{source}: '{level}' must map class ids to labels")
    entries = []
    for key, label in table.items():
        text = str(key)
        if not (_is_id(key) or text.isdigit()):
            raise FileFormatError(f"{source}: '{level}' key {key!r} is not a class id")
        if not (isinstance(label, str) and label.strip()):
            raise FileFormatError(f"{source}: class {key} has no label ({label!r})")
        entries.append((int(text), label))
    return entries


def _listed(ids: Sequence[int], most: int = 8) -> str:
    shown = ", ".join(map(str, ids[:most]))
    return shown + (f" and {len(ids) - most} more" if len(ids) > most else "")


@dataclass(frozen=True)
class Letterbox:
    """How a frame was fitted into the model's input: scaled by ``scale_x``, ``scale_y``, then
    shifted by ``left``, ``top`` pixels of padding."""

    scale_x: float
    scale_y: float
    left: int
    top: int

    def to_frame(self, boxes: NDArray[np.float64]) -> NDArray[np.float64]:
        """``(n, 4)`` corner boxes from input pixels back to frame pixels."""
        offset = np.array([self.left, self.top, self.left, self.top], dtype=np.float64)
        scale = np.array([self.scale_x, self.scale_y, self.scale_x, self.scale_y])
        return (boxes - offset) / scale


def frame_image(frame: Frame) -> NDArray[np.float32]:
    """The frame's picture as ``(h, w, 3)`` RGB in [0, 1]: its ``rgb`` image when it has one
    (uint8, or float in [0, 1]), else the grey ``intensity`` in all three channels."""
    rgb = getattr(frame, "rgb", None)
    image = np.asarray(rgb if rgb is not None else frame.grey())
    height, width = frame.shape
    if image.ndim == 2:
        image = np.repeat(image[:, :, None], 3, axis=2)
    if image.shape != (height, width, 3):
        raise InvalidInputError(
            f"the frame's image is {image.shape}, expected ({height}, {width}) grey or "
            f"({height}, {width}, 3) RGB, the size of its depth"
        )
    if image.dtype == np.uint8:
        return image.astype(np.float32) / np.float32(255)
    if not np.issubdtype(image.dtype, np.floating) or not np.isfinite(image).all():
        raise InvalidInputError(f"the frame's image must be uint8 or finite floats ({image.dtype})")
    return np.clip(image, 0, 1).astype(np.float32)


def letterbox(image: NDArray[np.float32], size: tuple[int, int]) -> tuple[NDArray, Letterbox]:
    """``image`` (h, w, 3) as the model's ``(1, 3, H, W)`` input, as YOLOv8's letterbox makes it:
    scaled to fit ``size = (H, W)`` (up or down), centred, padded with grey."""
    height, width = image.shape[:2]
    rows, cols = size
    ratio = min(rows / height, cols / width)
    new_w, new_h = max(1, round(width * ratio)), max(1, round(height * ratio))
    top, left = round((rows - new_h) / 2 - 0.1), round((cols - new_w) / 2 - 0.1)
    resized: NDArray[Any] = image
    if (new_w, new_h) != (width, height):
        resized = cv2.resize(image, (new_w, new_h), interpolation=cv2.INTER_LINEAR)
    canvas = np.full((rows, cols, 3), PAD_VALUE, dtype=np.float32)
    canvas[top : top + new_h, left : left + new_w] = resized
    tensor = np.ascontiguousarray(canvas.transpose(2, 0, 1)[None])
    return tensor, Letterbox(new_w / width, new_h / height, left, top)


def nms(boxes: NDArray[np.float64], scores: NDArray[np.float64], iou: float) -> list[int]:
    """Indices of ``boxes`` (corners) kept by greedy non-maximum suppression, best first."""
    order = np.argsort(-scores, kind="stable")
    areas = np.prod(np.clip(boxes[:, 2:] - boxes[:, :2], 0, None), axis=1)
    keep: list[int] = []
    while order.size:
        best, rest = order[0], order[1:]
        keep.append(int(best))
        low = np.maximum(boxes[best, :2], boxes[rest, :2])
        high = np.minimum(boxes[best, 2:], boxes[rest, 2:])
        inter = np.prod(np.clip(high - low, 0, None), axis=1)
        overlap = inter / np.maximum(areas[best] + areas[rest] - inter, 1e-9)
        order = rest[overlap <= iou]
    return keep


@dataclass(frozen=True)
class ModelLayout:
    """What a YOLOv8-seg ONNX file declares: its input's name and fixed size ``(H, W)``, its
    class and mask-coefficient counts, and which output holds candidates and prototypes."""

    input_name: str
    input_size: tuple[int, int]
    classes: int
    coefficients: int
    candidates: str
    prototypes: str

    def run(self, session: Any, tensor: NDArray[np.float32]) -> tuple[NDArray, NDArray]:
        """Candidates ``(N, 4 + nc + nm)`` and prototypes ``(nm, mh, mw)`` of one input."""
        out0, out1 = session.run([self.candidates, self.prototypes], {self.input_name: tensor})
        rows = 4 + self.classes + self.coefficients
        if (
            out0.shape[:2] != (1, rows)
            or out1.shape[:2] != (1, self.coefficients)
            or ((out0.ndim, out1.ndim) != (3, 4))
        ):
            raise FileFormatError(
                f"the model gave {self.candidates} {list(out0.shape)} and {self.prototypes} "
                f"{list(out1.shape)}, expected [1, {rows}, N] and [1, {self.coefficients}, mh, mw]"
            )
        return out0[0].T.astype(np.float64), out1[0].astype(np.float32)


def open_session(path: Path, threads: int | None = None) -> tuple[Any, ModelLayout]:
    """An onnxruntime CPU session of the model file at ``path``, and its checked layout."""
    session = open_onnx_session(path, threads)
    return session, model_layout(session, path.name)


def open_onnx_session(path: Path, threads: int | None = None) -> Any:
    """An onnxruntime CPU session of any ONNX file at ``path``; a missing or broken file is a
    one-line :class:`FileFormatError` (shared with :mod:`.learned`)."""
    if not path.is_file():
        raise FileFormatError(f"{path}: no such model file")
    import onnxruntime  # noqa: PLC0415 - 0.15 s to import, paid by runs that use a model only

    options = onnxruntime.SessionOptions()
    options.log_severity_level = 3  # errors only: a model's warnings are not the user's
    if threads is not None:
        options.intra_op_num_threads, options.inter_op_num_threads = threads, 1
    try:
        session = onnxruntime.InferenceSession(
            str(path), options, providers=["CPUExecutionProvider"]
        )
    except Exception as exc:  # onnxruntime has a type for every way a file can be broken
        reason = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
        raise FileFormatError(f"{path}: not an ONNX model onnxruntime can run ({reason})") from None
    return session


def model_layout(session: Any, source: str) -> ModelLayout:
    """The layout a session's inputs and outputs declare, refused with what was expected and
    what was found when it is not YOLOv8-seg's."""
    inputs, outputs = session.get_inputs(), session.get_outputs()
    if len(inputs) != 1 or not _is_image(inputs[0]):
        raise FileFormatError(
            f"{source}: expected one input 'images' tensor(float) [1, 3, H, W] with a fixed H "
            f"and W, found {_described(inputs)}"
        )
    named = {o.name: o for o in outputs}
    pair: list[Any] = [named.get("output0"), named.get("output1")]
    if None in pair:  # another exporter's names: the candidates have 3 axes, prototypes 4
        pair = sorted(outputs, key=lambda o: len(o.shape))
    channels, coefficients = _fixed(pair[0], 3), _fixed(pair[-1], 4)
    if len(outputs) != 2 or not (channels and coefficients and channels > 4 + coefficients):
        raise FileFormatError(
            f"{source}: expected YOLOv8-seg outputs output0 [1, 4 + nc + nm, N] and output1 "
            f"[1, nm, mh, mw] with fixed nc and nm, found {_described(outputs)}"
        )
    size = (int(inputs[0].shape[2]), int(inputs[0].shape[3]))
    classes = channels - 4 - coefficients
    return ModelLayout(inputs[0].name, size, classes, coefficients, pair[0].name, pair[1].name)


def _is_image(arg: Any) -> bool:
    """A float input ``[1 or a batch symbol, 3, H, W]`` with fixed ``H`` and ``W``."""
    shape = list(arg.shape)
    if arg.type != "tensor(float)" or len(shape) != 4 or shape[1] != 3:
        return False
    batch_ok = shape[0] == 1 or not isinstance(shape[0], int)
    return batch_ok and all(isinstance(d, int) and d > 0 for d in shape[2:])


def _fixed(arg: Any, rank: int) -> int | None:
    """The fixed size of axis 1 of a float output of ``rank`` axes; None otherwise."""
    if arg is None or arg.type != "tensor(float)" or len(arg.shape) != rank:
        return None
    size = arg.shape[1]
    return size if isinstance(size, int) and size > 0 else None


def _described(args: Sequence[Any]) -> str:
    return ", ".join(f"{a.name} {a.type} {list(a.shape)}" for a in args) or "none"


@dataclass(eq=False)
class YoloSegDetector:
    """A YOLOv8-seg ONNX model as a :class:`~seminspect.sensors.Detector`; make it with
    :meth:`load`. Detections carry ``instance_id`` -1: a model knows no ground truth."""

    session: Any  # onnxruntime.InferenceSession
    layout: ModelLayout
    class_map: ClassMap
    name: str
    score_threshold: float = 0.25
    iou_threshold: float = 0.7
    max_detections: int = 300
    #: A platform renders the image of every frame this detector is given.
    reads_image: ClassVar[bool] = True
    _last: tuple[Frame, Letterbox, NDArray, NDArray] | None = field(
        default=None, init=False, repr=False
    )

    def __post_init__(self) -> None:
        for what, value in (("score", self.score_threshold), ("IoU", self.iou_threshold)):
            if not (math.isfinite(value) and 0 < value < 1):
                raise InvalidInputError(f"the {what} threshold must lie in (0, 1), got {value}")
        if self.max_detections < 1:
            raise InvalidInputError(f"max_detections must be >= 1, got {self.max_detections}")
        self.class_map.check(self.layout.classes, self.name)

    @classmethod
    def load(
        cls,
        model: str | os.PathLike[str],
        class_map: str | os.PathLike[str] | ClassMap,
        *,
        score_threshold: float = 0.25,
        iou_threshold: float = 0.7,
        threads: int | None = None,
    ) -> YoloSegDetector:
        """The model file with its class map (a file or a :class:`ClassMap`); the thresholds
        are YOLOv8's prediction defaults; ``threads``: onnxruntime's (None: its own choice)."""
        path = Path(model)
        mapping = class_map if isinstance(class_map, ClassMap) else ClassMap.read(class_map)
        session, layout = open_session(path, threads)
        return cls(session, layout, mapping, f"onnx:{path.name}", score_threshold, iou_threshold)

    def detect(self, frame: Frame, level: Level, labels: Sequence[str]) -> list[Detection]:
        """The model's detections of ``level`` whose label is in ``labels``, best first."""
        names = set(labels)
        wanted = {
            k for k, (label, of) in self.class_map.classes.items() if of == level and label in names
        }
        if np.isnan(frame.depth).any():
            raise InvalidInputError("the frame's depth holds NaN; use inf where nothing was seen")
        fit, candidates, protos = self._outputs(frame)
        if not wanted:
            return []
        kept = self._kept(candidates, wanted)
        return self._detections(frame, fit, candidates[kept], protos)

    def _outputs(self, frame: Frame) -> tuple[Letterbox, NDArray, NDArray]:
        """The model's outputs for ``frame``, kept for the last frame: a mission asks for the
        objects and then the parts of one frame, and the model sees both at once."""
        last = self._last
        if last is not None and last[0] is frame:
            return last[1:]
        tensor, fit = letterbox(frame_image(frame), self.layout.input_size)
        candidates, protos = self.layout.run(self.session, tensor)
        self._last = (frame, fit, candidates, protos)
        return fit, candidates, protos

    def _kept(self, candidates: NDArray[np.float64], wanted: set[int]) -> NDArray[np.intp]:
        """Rows of ``candidates`` above the score threshold, of a wanted class, after NMS
        within each class (an object's box does not suppress an overlapping part's)."""
        scores = candidates[:, 4 : 4 + self.layout.classes]
        best = scores.argmax(axis=1)
        confidence = scores[np.arange(len(best)), best]
        rows = np.flatnonzero((confidence > self.score_threshold) & np.isin(best, list(wanted)))
        boxes = _corners(candidates[:, :4])
        kept: list[int] = []
        for value in np.unique(best[rows]):
            own = rows[best[rows] == value]
            kept += [int(own[i]) for i in nms(boxes[own], confidence[own], self.iou_threshold)]
        kept.sort(key=lambda row: -confidence[row])
        return np.asarray(kept[: self.max_detections], dtype=np.intp)

    def _detections(
        self,
        frame: Frame,
        fit: Letterbox,
        chosen: NDArray[np.float64],
        protos: NDArray[np.float32],
    ) -> list[Detection]:
        classes = self.layout.classes
        coefficients = chosen[:, 4 + classes :].astype(np.float32)
        masks = _sigmoid(coefficients @ protos.reshape(len(protos), -1))
        masks = masks.reshape(len(chosen), *protos.shape[1:])
        boxes = fit.to_frame(_corners(chosen[:, :4]))
        found = []
        for row, mask, box in zip(chosen, masks, boxes, strict=True):
            window = _frame_mask(mask, box, fit, self.layout.input_size, frame.shape)
            if window is None:
                continue
            scores = row[4 : 4 + classes]
            label, level = self.class_map.classes[int(np.argmax(scores))]
            found.append(
                window_detection(label, level, min(float(scores.max()), 1.0), window, frame)
            )
        return found


def _corners(boxes: NDArray[np.float64]) -> NDArray[np.float64]:
    """Centre-size boxes ``(cx, cy, w, h)`` as corners ``(x0, y0, x1, y1)``."""
    half = boxes[:, 2:4] / 2
    return np.concatenate([boxes[:, :2] - half, boxes[:, :2] + half], axis=1)


def _sigmoid(values: NDArray[np.float32]) -> NDArray[np.float32]:
    return (1 / (1 + np.exp(-np.clip(values, -50, 50)))).astype(np.float32, copy=False)


def _frame_mask(
    mask: NDArray[np.float32],
    box: NDArray[np.float64],
    fit: Letterbox,
    input_size: tuple[int, int],
    shape: tuple[int, int],
) -> tuple[NDArray[np.bool_], int, int] | None:
    """A prototype-resolution mask as frame pixels inside its box: the box's window of the
    frame and the window's first column and row (None if no pixel is left).

    One affine warp per mask takes each frame pixel centre through the letterbox to the
    prototype grid (half-pixel centres, as the bilinear upsampling of YOLOv8), sampling only
    the box's window; the window is then thresholded at 0.5.
    """
    height, width = shape
    x0, x1 = (int(np.clip(math.ceil(v), 0, width)) for v in (box[0], box[2]))
    y0, y1 = (int(np.clip(math.ceil(v), 0, height)) for v in (box[1], box[3]))
    if x1 <= x0 or y1 <= y0:
        return None
    sx, sy = mask.shape[1] / input_size[1], mask.shape[0] / input_size[0]
    ax, ay = fit.scale_x * sx, fit.scale_y * sy
    bx = (0.5 * fit.scale_x + fit.left) * sx - 0.5 + ax * x0
    by = (0.5 * fit.scale_y + fit.top) * sy - 0.5 + ay * y0
    warp = np.array([[ax, 0.0, bx], [0.0, ay, by]])
    window = cv2.warpAffine(
        mask,
        warp,
        (x1 - x0, y1 - y0),
        flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
        borderMode=cv2.BORDER_REPLICATE,
    )
    inside = window > 0.5
    return (inside, x0, y0) if inside.any() else None


def window_detection(
    label: str,
    level: Level,
    score: float,
    window: tuple[NDArray[np.bool_], int, int],
    frame: Frame,
) -> Detection:
    """A detection of the mask ``window`` (pixels, first column, first row) in ``frame``; its
    box, area and depth are read off the window, not the whole frame."""
    inside, x0, y0 = window
    rows, cols = np.flatnonzero(inside.any(axis=1)), np.flatnonzero(inside.any(axis=0))
    bbox = (x0 + int(cols[0]), y0 + int(rows[0]), x0 + int(cols[-1]) + 1, y0 + int(rows[-1]) + 1)
    height, width = inside.shape
    depths = frame.depth[y0 : y0 + height, x0 : x0 + width][inside]
    depths = depths[np.isfinite(depths)]
    depth = float(np.median(depths)) if len(depths) else math.inf
    mask = np.zeros(frame.shape, dtype=bool)
    mask[y0 : y0 + height, x0 : x0 + width] = inside
    return Detection(label, mask, int(inside.sum()), score, bbox, -1, level, depth)
