"""Sensor and odometry noise: one validated model, two presets.

Every field names the fault it simulates and its unit; the defaults are the ``ideal`` preset
(no noise at all). ``realistic`` uses magnitudes typical of the hardware of 000 Sec VI-A (a
RealSense D455 depth camera, a VLP-16 LiDAR, a YOLOv8-seg segmentation model and legged
odometry); every number is a documented choice, not a measurement.

Missed detections combine three causes, each independently (000 Sec VII-A blames one missed
target on distant views)::

    p_miss = 1 - (1 - miss_probability - miss_per_metre * range)
               * (1 - exp(-area_px / miss_area_scale_px))

Depth noise grows linearly with range, as in 004 Sec III-E: ``sigma(d) = depth_noise_m +
depth_noise_per_m * d``. Odometry drift is a random walk whose variance grows with the distance
travelled and the angle turned, so splitting a motion into pieces does not change it.
"""

from __future__ import annotations

import math
from concurrent.futures import Future

import numpy as np
from numpy.typing import DTypeLike, NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from seminspect.core.errors import InvalidInputError
from seminspect.core.names import unknown_name
from seminspect.core.threads import thread_pool


class NoiseModel(BaseModel):
    """Faults of the simulated sensors and odometry (defaults: the ``ideal`` preset)."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    mask_erosion_px: int = Field(
        0, ge=0, le=50, description="pixels removed from every mask border (under-segmentation)"
    )
    mask_bleed_px: int = Field(
        0,
        ge=0,
        le=50,
        description="pixels a mask grows into the background around it (over-segmentation)",
    )
    miss_probability: float = Field(
        0.0, ge=0, le=1, description="probability of missing a visible object at zero range"
    )
    miss_per_metre: float = Field(
        0.0, ge=0, le=1, description="added miss probability per metre of median mask depth"
    )
    miss_area_scale_px: float = Field(
        0.0,
        ge=0,
        description="mask area [px] below which objects are mostly missed: p = exp(-area/scale)",
    )
    min_mask_area_px: int = Field(
        1, ge=1, description="masks smaller than this many pixels are never reported"
    )
    false_positives_per_frame: float = Field(
        0.0, ge=0, le=20, description="mean number of spurious detections per frame (Poisson)"
    )
    score_mean: float = Field(
        1.0, gt=0, le=1, description="mean confidence score of a true detection"
    )
    score_sigma: float = Field(
        0.0, ge=0, le=1, description="standard deviation of the confidence score"
    )
    false_positive_score: float = Field(
        0.5, gt=0, le=1, description="mean confidence of a false positive (sigma 0.1)"
    )
    image_time_offset_s: float = Field(
        0.0,
        ge=0,
        le=5,
        description="image lags odometry by this many seconds (000 Sec VII-B desync)",
    )
    depth_noise_m: float = Field(0.0, ge=0, le=1, description="depth noise sigma at zero range [m]")
    depth_noise_per_m: float = Field(
        0.0, ge=0, le=0.2, description="depth noise sigma added per metre of range [m/m]"
    )
    intensity_noise: float = Field(
        0.0, ge=0, le=50, description="sigma of pixel noise on the intensity image [grey levels]"
    )
    image_noise_float32: bool = Field(
        False,
        description="draw the image noise as float32 deviates: faster, but other numbers from "
        "the same seed than the float64 default (results differ from published runs)",
    )
    lidar_range_noise_m: float = Field(
        0.0, ge=0, le=1, description="sigma of LiDAR range noise [m]"
    )
    odometry_drift_per_m: float = Field(
        0.0,
        ge=0,
        le=1,
        description="position random walk: sigma grows as this times sqrt(metres travelled)",
    )
    odometry_drift_per_rad: float = Field(
        0.0,
        ge=0,
        le=1,
        description="heading random walk: sigma grows as this times sqrt(radians turned)",
    )

    def depth_sigma(self, depth: float) -> float:
        """Standard deviation of the depth noise at ``depth`` metres."""
        return self.depth_noise_m + self.depth_noise_per_m * depth

    def miss_chance(self, median_depth: float, area_px: float) -> float:
        """Probability of missing an object seen at ``median_depth`` with ``area_px`` pixels."""
        by_range = min(1.0, self.miss_probability + self.miss_per_metre * median_depth)
        by_area = math.exp(-area_px / self.miss_area_scale_px) if self.miss_area_scale_px else 0.0
        return 1.0 - (1.0 - by_range) * (1.0 - by_area)

    @property
    def is_ideal(self) -> bool:
        """Whether this model changes nothing (no random draws are needed)."""
        return self.model_copy(update={"image_noise_float32": False}) == NoiseModel()


class NormalStream:
    """The standard normal deviates of one generator, in its order, drawn ahead on a thread.

    numpy's generators give the same deviates whatever the sizes they are drawn in (``n``
    then ``m`` equal one draw of ``n + m``), so while a mission does other work a worker
    thread draws the next ``chunk`` and :meth:`standard_normal` hands them out: the numbers
    of drawing each frame's noise when it is needed, off the mission's own thread. The
    generator must not be drawn from elsewhere once the stream has it.

    Args:
        rng: the generator (the stream owns it from now on).
        threads: the pool to draw on (``core.threads.thread_pool``); 1 draws in the caller.
        chunk: deviates drawn at a time.
    """

    def __init__(self, rng: np.random.Generator, threads: int, chunk: int = 1 << 20) -> None:
        self._rng = rng
        self._threads = threads
        self._chunk = chunk
        self._dtype: np.dtype | None = None
        self._buffer = np.empty(0)
        self._ahead: Future[NDArray] | None = None

    def standard_normal(self, size: int, dtype: DTypeLike = np.float64) -> NDArray:
        """The next ``size`` deviates, as ``Generator.standard_normal(size, dtype)`` gives them
        (every call with the same ``dtype``)."""
        wanted = np.dtype(dtype)
        if self._dtype is None:
            self._dtype = wanted
            self._buffer = np.empty(0, dtype=wanted)
        elif wanted != self._dtype:
            raise InvalidInputError(f"a stream of {self._dtype} deviates cannot give {wanted}")
        pieces = []
        while size > len(self._buffer):
            pieces.append(self._buffer)
            size -= len(self._buffer)
            self._buffer = self._next_chunk()
        pieces.append(self._buffer[:size])
        self._buffer = self._buffer[size:]
        return pieces[0] if len(pieces) == 1 else np.concatenate(pieces)

    def _next_chunk(self) -> NDArray:
        """The chunk drawn ahead (or, the first time or on one thread, drawn now), and the
        next one started."""
        chunk = self._ahead.result() if self._ahead is not None else self._draw()
        self._ahead = thread_pool(self._threads).submit(self._draw) if self._threads > 1 else None
        return chunk

    def _draw(self) -> NDArray:
        return self._rng.standard_normal(self._chunk, dtype=self._dtype)  # type: ignore[arg-type]


def require_rng(rng: np.random.Generator | None) -> np.random.Generator:
    """The generator a noisy sensor draws from; refuse to invent one (runs must be seeded)."""
    if rng is None:
        raise InvalidInputError(
            "a noisy sensor needs a random generator: pass rng=make_rng(seed, 'sensors', ...)"
        )
    return rng


PRESETS: dict[str, NoiseModel] = {
    "ideal": NoiseModel(),
    "realistic": NoiseModel(
        mask_erosion_px=2,
        mask_bleed_px=2,
        miss_probability=0.02,
        miss_per_metre=0.01,
        miss_area_scale_px=150.0,
        min_mask_area_px=30,
        false_positives_per_frame=0.1,
        score_mean=0.85,
        score_sigma=0.07,
        false_positive_score=0.45,
        image_time_offset_s=0.1,
        depth_noise_m=0.005,
        depth_noise_per_m=0.01,
        intensity_noise=2.0,
        lidar_range_noise_m=0.03,
        odometry_drift_per_m=0.02,
        odometry_drift_per_rad=0.01,
    ),
}


def noise_preset(name: str) -> NoiseModel:
    """The ``ideal`` or ``realistic`` noise model."""
    try:
        return PRESETS[name]
    except KeyError:
        raise unknown_name("noise preset", name, PRESETS) from None


def make_noise(values: dict[str, float | int], base: str = "ideal") -> NoiseModel:
    """A preset with some fields changed, validated into one readable error line."""
    try:
        return NoiseModel(**(noise_preset(base).model_dump() | values))
    except ValidationError as exc:
        first = exc.errors()[0]
        where = ".".join(str(part) for part in first["loc"]) or "noise"
        raise InvalidInputError(f"invalid noise setting {where}: {first['msg']}") from None
