"""The learned detector at run time: the ONNX export of :mod:`.segnet` as a
:class:`~seminspect.sensors.Detector`, with onnxruntime, numpy and OpenCV only (no torch).

A frame's image (``rgb``, else the grey intensity in three channels) is resized to the model's
fixed input (stretched if its aspect differs), run once for both levels, and the class, part
and seam probabilities are resized back to the frame (bilinear). Objects are the connected
components of each class's argmax mask with the predicted seams cut out (4-connected), the seam
pixels then given to the nearest component within :data:`SEAM_REACH` pixels; parts are the
connected components of each part's mask on target pixels, split where they cross from one
object into another. Objects under ``min_area_px`` and parts under ``min_part_px`` pixels are
dropped. A detection's score is its label's mean probability over the mask; ``instance_id`` is
-1 (a model knows no ground truth).

The model file names its labels in its ONNX ``metadata_props`` (:data:`METADATA_KEYS`, written
by :func:`.segnet_io.export_onnx`), so it needs no class map.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import cv2
import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.perception.yolo_seg import frame_image, open_onnx_session, window_detection
from seminspect.sensors.camera import Frame
from seminspect.sensors.segmentation import Detection, Level

MODEL_FORMAT = "seminspect.segnet"
MODEL_VERSION = 1
#: The metadata that marks a model as ours: format, version, and classes and parts as JSON.
METADATA_KEYS = ("seminspect.format", "seminspect.version", "classes", "parts")
INPUT_NAME = "images"
OUTPUT_NAMES = ("classes", "parts", "edges")
#: How far (pixels) a seam pixel may lie from the object it is given to.
SEAM_REACH = 3.0


@dataclass(frozen=True)
class _Maps:
    """One frame's model outputs at frame resolution, and the objects found in them."""

    class_prob: NDArray[np.float32]  # (h, w, C)
    part_prob: NDArray[np.float32]  # (h, w, P)
    owner: NDArray[np.int32]  # object index + 1 per pixel, 0: none
    objects: list[Detection]


@dataclass(eq=False)
class LearnedDetector:
    """A model exported by :func:`~.segnet_io.export_onnx`; make it with :meth:`load`."""

    session: Any  # onnxruntime.InferenceSession
    input_size: tuple[int, int]  # (H, W)
    classes: tuple[str, ...]
    parts: tuple[str, ...]
    name: str
    min_area_px: int = 20
    min_part_px: int = 8
    seam_threshold: float = 0.5
    #: A platform renders the image of every frame this detector is given.
    reads_image: ClassVar[bool] = True
    _last: tuple[Frame, _Maps] | None = field(default=None, init=False, repr=False)
    _parts: list[Detection] | None = field(default=None, init=False, repr=False)

    @classmethod
    def load(
        cls,
        model: str | os.PathLike[str],
        *,
        min_area_px: int = 20,
        min_part_px: int = 8,
        threads: int | None = None,
    ) -> LearnedDetector:
        """The model file; ``min_area_px``, ``min_part_px``: the smallest object and part kept,
        in frame pixels; ``threads``: onnxruntime's (None: its own choice)."""
        path = Path(model)
        if min(min_area_px, min_part_px) < 1:
            raise InvalidInputError(
                f"min_area_px and min_part_px must be >= 1, got {min_area_px}, {min_part_px}"
            )
        session = open_onnx_session(path, threads)
        classes, parts = _vocabulary(session, path.name)
        size = _check_layout(session, path.name, len(classes), len(parts))
        name = f"learned:{path.name}"
        return cls(session, size, classes, parts, name, min_area_px, min_part_px)

    def detect(self, frame: Frame, level: Level, labels: Sequence[str]) -> list[Detection]:
        """The model's objects (``instance``: by class) or parts (``part``: by part name)
        whose label is in ``labels``, best first."""
        maps = self._maps(frame)
        wanted = set(labels)
        found = maps.objects if level == "instance" else self._part_detections(frame, maps)
        return [d for d in found if d.label in wanted]

    def _maps(self, frame: Frame) -> _Maps:
        """The outputs for ``frame``, kept for the last frame: a mission asks for the objects
        and then the parts of one frame, and one forward pass serves both."""
        if self._last is not None and self._last[0] is frame:
            return self._last[1]
        if np.isnan(frame.depth).any():
            raise InvalidInputError("the frame's depth holds NaN; use inf where nothing was seen")
        if getattr(frame, "rgb", None) is None and frame.intensity is None:
            raise InvalidInputError(
                "the frame has no image (neither rgb nor intensity): the learned detector "
                "reads pixels"
            )
        class_prob, part_prob, seam = self._run(frame_image(frame), frame.shape)
        owner, objects = self._objects(frame, class_prob, seam)
        maps = _Maps(class_prob, part_prob, owner, objects)
        self._last, self._parts = (frame, maps), None
        return maps

    def _run(
        self, image: NDArray[np.float32], shape: tuple[int, int]
    ) -> tuple[NDArray[np.float32], NDArray[np.float32], NDArray[np.bool_]]:
        """The model's probabilities for ``image``, resized to ``shape`` (h, w), channels last."""
        rows, cols = self.input_size
        fitted: NDArray[Any] = image
        if image.shape[:2] != (rows, cols):
            method = cv2.INTER_AREA if image.shape[0] > rows else cv2.INTER_LINEAR
            fitted = cv2.resize(image, (cols, rows), interpolation=method)
        tensor = np.ascontiguousarray(fitted.transpose(2, 0, 1)[None], dtype=np.float32)
        outputs = self.session.run(list(OUTPUT_NAMES), {INPUT_NAME: tensor})
        back = [_to_frame(out[0], shape) for out in outputs]
        return back[0], back[1], back[2][..., 0] > self.seam_threshold

    def _objects(
        self, frame: Frame, class_prob: NDArray[np.float32], seam: NDArray[np.bool_]
    ) -> tuple[NDArray[np.int32], list[Detection]]:
        """Each class's components, seams cut out and given back; the owner image numbers
        the objects kept from 1."""
        best = class_prob.argmax(axis=2)
        owner = np.zeros(best.shape, dtype=np.int32)
        objects: list[Detection] = []
        for value in np.unique(best):
            if value == 0:
                continue
            mask = best == value
            for piece in _pieces(_split_at_seams(mask, seam), self.min_area_px):
                label = str(self.classes[value])
                objects.append(_detection(label, "instance", class_prob[..., value], piece, frame))
                owner[piece[0]][piece[1]] = len(objects)
        order = sorted(range(len(objects)), key=lambda i: -objects[i].score)
        return _renumbered(owner, order), [objects[i] for i in order]

    def _part_detections(self, frame: Frame, maps: _Maps) -> list[Detection]:
        """Each part's components on the objects' pixels, split between objects."""
        if self._parts is not None:
            return self._parts
        best = np.where(maps.owner > 0, maps.part_prob.argmax(axis=2), 0)
        found: list[Detection] = []
        for value in np.unique(best):
            if value == 0:
                continue
            mask = best == value
            components = _components(mask, 8)
            key = np.where(
                mask, components.astype(np.int64) * (len(maps.objects) + 1) + maps.owner, 0
            )
            keys, pieces = np.unique(key, return_inverse=True)
            pieces = pieces.reshape(key.shape) + (0 if keys[0] == 0 else 1)
            for piece in _pieces(pieces, self.min_part_px):
                label = str(self.parts[value])
                found.append(_detection(label, "part", maps.part_prob[..., value], piece, frame))
        found.sort(key=lambda d: -d.score)
        self._parts = found
        return found


def _pieces(
    components: NDArray[np.integer], min_area: int
) -> Iterator[tuple[tuple[slice, slice], NDArray[np.bool_]]]:
    """``(window, pixels inside it)`` of each numbered component of at least ``min_area``."""
    for index, window in enumerate(ndimage.find_objects(components), start=1):
        if window is not None:
            inside = components[window] == index
            if int(inside.sum()) >= min_area:
                yield window, inside


def _detection(
    label: str,
    level: Level,
    prob: NDArray[np.float32],
    piece: tuple[tuple[slice, slice], NDArray[np.bool_]],
    frame: Frame,
) -> Detection:
    """The detection of the pixels ``inside`` the ``window`` of ``piece``, scored by the mean
    of its label's probability ``prob`` over them."""
    window, inside = piece
    score = min(max(float(prob[window][inside].mean()), 1e-6), 1.0)
    x0, y0 = int(window[1].start), int(window[0].start)
    return window_detection(label, level, score, (inside, x0, y0), frame)


def _to_frame(output: NDArray[np.float32], shape: tuple[int, int]) -> NDArray[np.float32]:
    """A ``(C, H, W)`` map as ``(h, w, C)`` at the frame's size (bilinear)."""
    channels_last: NDArray[Any] = np.ascontiguousarray(output.transpose(1, 2, 0), np.float32)
    if channels_last.shape[:2] != shape:
        channels_last = cv2.resize(
            channels_last, (shape[1], shape[0]), interpolation=cv2.INTER_LINEAR
        )
    return channels_last.reshape(shape[0], shape[1], output.shape[0])


def _split_at_seams(mask: NDArray[np.bool_], seam: NDArray[np.bool_]) -> NDArray[np.int32]:
    """Components of ``mask`` without its seam pixels (4-connected); each seam pixel then joins
    the nearest component within :data:`SEAM_REACH`. A mask with no seams is 8-connected."""
    cut = mask & seam
    if not cut.any():
        return _components(mask, 8)
    components = _components(mask & ~seam, 4)
    distance, (rows, cols) = ndimage.distance_transform_edt(components == 0, return_indices=True)
    near = cut & (distance <= SEAM_REACH)
    components[near] = components[rows[near], cols[near]]
    return components


def _components(mask: NDArray[np.bool_], connectivity: int) -> NDArray[np.int32]:
    labels = cv2.connectedComponents(mask.astype(np.uint8), connectivity=connectivity)[1]
    return np.asarray(labels, dtype=np.int32)


def _renumbered(owner: NDArray[np.int32], order: list[int]) -> NDArray[np.int32]:
    """``owner`` numbered in ``order`` (object ``order[k]`` becomes ``k + 1``)."""
    table = np.zeros(len(order) + 1, dtype=np.int32)
    table[np.asarray(order, dtype=np.int64) + 1] = np.arange(1, len(order) + 1)
    return table[owner]


def _vocabulary(session: Any, source: str) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """The classes and parts the model's metadata names; a model without them is not ours."""
    meta = dict(session.get_modelmeta().custom_metadata_map)
    if meta.get(METADATA_KEYS[0]) != MODEL_FORMAT:
        raise FileFormatError(
            f"{source}: not a seminspect learned-detector model (its metadata has no "
            f"{METADATA_KEYS[0]}={MODEL_FORMAT}: export one with 'seminspect perception export'; "
            "a YOLOv8-seg export needs its class map, --class-map)"
        )
    if meta.get(METADATA_KEYS[1]) != str(MODEL_VERSION):
        raise FileFormatError(
            f"{source}: learned-detector version {meta.get(METADATA_KEYS[1])!r} is not "
            f"supported (supported: {MODEL_VERSION})"
        )
    names = []
    for key in METADATA_KEYS[2:]:
        try:
            value = json.loads(meta.get(key, ""))
        except json.JSONDecodeError:
            value = None
        if not (isinstance(value, list) and value and all(isinstance(v, str) for v in value)):
            raise FileFormatError(f"{source}: its metadata '{key}' is not a list of names")
        names.append(tuple(value))
    return names[0], names[1]


def _check_layout(session: Any, source: str, classes: int, parts: int) -> tuple[int, int]:
    """The fixed input size ``(H, W)``, once the inputs and outputs are those of an export."""
    inputs = session.get_inputs()
    shape = list(inputs[0].shape) if len(inputs) == 1 else []
    if not (
        len(shape) == 4
        and inputs[0].name == INPUT_NAME
        and shape[:2] == [1, 3]
        and all(isinstance(d, int) and d > 0 for d in shape[2:])
    ):
        found = ", ".join(f"{i.name} {list(i.shape)}" for i in inputs) or "none"
        raise FileFormatError(f"{source}: expected one input 'images' [1, 3, H, W], found {found}")
    rows, cols = int(shape[2]), int(shape[3])
    expected = {"classes": classes, "parts": parts, "edges": 1}
    found_out = {o.name: list(o.shape) for o in session.get_outputs()}
    for name, channels in expected.items():
        if found_out.get(name) != [1, channels, rows, cols]:
            raise FileFormatError(
                f"{source}: expected output {name} [1, {channels}, {rows}, {cols}], found "
                f"{found_out.get(name, 'none')}"
            )
    return rows, cols
