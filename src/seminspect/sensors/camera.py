"""The depth + segmentation + intensity camera, rendered by ray casting.

Frames: the camera looks along its body +X axis with +Y to the left and +Z up; pixel ``(u, v)``
runs right and down. In the usual optical frame (x right, y down, z forward) the intrinsics
``K`` map a point to pixel coordinates, with square pixels and the principal point at the image
centre. ``Frame.depth`` is the distance along the optical axis (a depth camera's z), not along
the ray.

The defaults are the simulated camera of 000 Table 1: 640 x 480 pixels, a 69.4 deg horizontal
field of view and d_max = 30 m (the experimental camera has 86 deg).
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass, field, replace
from functools import cached_property

import numba
import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial.transform import Rotation

from seminspect.core.errors import InvalidInputError
from seminspect.core.params import InspectionParams
from seminspect.core.threads import rotate_rows, run_dealt
from seminspect.geometry.transforms import Quat, Vec3, as_point, as_quaternion
from seminspect.sensors.appearance import Appearance, colour_image
from seminspect.sensors.noise import NoiseModel, NormalStream, require_rng
from seminspect.sensors.shading import OCTAVE_WEIGHTS, OCTAVES, shade_hits, surface_tables
from seminspect.worlds import World


@dataclass(frozen=True)
class CameraModel:
    """A pinhole camera: image size, horizontal field of view and maximum range."""

    width: int = 640
    height: int = 480
    hfov_deg: float = 69.4
    max_range: float = 30.0

    def __post_init__(self) -> None:
        if not (isinstance(self.width, int) and isinstance(self.height, int)):
            raise InvalidInputError("camera width and height must be integers")
        if not (1 <= self.width <= 8192 and 1 <= self.height <= 8192):
            raise InvalidInputError(f"camera size {self.width}x{self.height} is out of range")
        if not (math.isfinite(self.hfov_deg) and 1.0 <= self.hfov_deg <= 170.0):
            raise InvalidInputError(f"horizontal FOV must be 1-170 deg, got {self.hfov_deg}")
        if not (math.isfinite(self.max_range) and self.max_range > 0):
            raise InvalidInputError(f"camera max range must be > 0, got {self.max_range}")

    @classmethod
    def from_params(cls, params: InspectionParams) -> CameraModel:
        """The camera described by 000 Table 1/2 symbols: alpha, I_w, I_h and d_max."""
        return cls(params.image_width, params.image_height, params.fov_deg, params.d_max)

    @property
    def fx(self) -> float:
        """Focal length in pixels."""
        return (self.width / 2) / math.tan(math.radians(self.hfov_deg) / 2)

    @property
    def cx(self) -> float:
        return (self.width - 1) / 2

    @property
    def cy(self) -> float:
        return (self.height - 1) / 2

    @property
    def K(self) -> NDArray[np.float64]:  # noqa: N802 - the usual symbol for intrinsics
        """3x3 intrinsics (optical frame, square pixels)."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fx, self.cy], [0.0, 0.0, 1.0]])

    @property
    def vfov_deg(self) -> float:
        """Vertical field of view that follows from the size and the horizontal one."""
        return math.degrees(2 * math.atan((self.height / 2) / self.fx))

    def scaled(self, stride: int) -> CameraModel:
        """The same field of view with every ``stride``-th pixel: a cheap render for mapping."""
        if not (isinstance(stride, int) and stride >= 1):
            raise InvalidInputError(f"stride must be a positive integer, got {stride!r}")
        if stride == 1:
            return self
        return replace(
            self, width=max(1, self.width // stride), height=max(1, self.height // stride)
        )

    @cached_property
    def rays(self) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
        """Unit ray directions in the body frame, ``(H*W, 3)`` row-major, and their x parts."""
        u, v = np.meshgrid(np.arange(self.width), np.arange(self.height))
        body = np.stack(
            [np.full(u.shape, self.fx), -(u - self.cx), -(v - self.cy)], axis=-1
        ).reshape(-1, 3)
        body /= np.linalg.norm(body, axis=1, keepdims=True)
        return body.astype(np.float32), np.ascontiguousarray(body[:, 0], dtype=np.float32)

    @cached_property
    def ray_limits(self) -> NDArray[np.float32]:
        """Length of each ray (row-major) at which its depth reaches ``max_range``."""
        return self.max_range / self.rays[1]


@dataclass(eq=False)
class Frame:
    """One rendered image: depth, labels and intensity, with the pose it was taken from.

    Attributes:
        depth: ``float32`` (H, W) metres along the optical axis; ``inf`` where nothing lies
            within the camera's range.
        instance: ``int32`` instance id per pixel (0: ground, background or nothing).
        class_id: ``int16`` index into ``World.class_names`` (0 where nothing was hit).
        part_id: ``int16`` index into ``World.part_names`` (0: no part).
        intensity: ``uint8`` grey image with a stable surface texture; None for a frame
            rendered without it (``render(..., intensity=False)``: see :meth:`grey`).
        face: ``int32`` index of the mesh face seen by each pixel (-1: none).
        position, orientation: the true camera pose the frame was rendered from.
        stamp: time the frame is tagged with (seconds).
        camera: the camera model (its scaled version for strided renders).
        odometry_position, odometry_orientation: the pose the robot believed it had at
            ``stamp``; equal to the true pose unless the caller passes odometry.
        rgb: ``uint8`` (H, W, 3) colour image under an
            :class:`~seminspect.sensors.appearance.Appearance`, without noise; None unless
            rendered with one (``render(..., appearance=...)``).
    """

    depth: NDArray[np.float32]
    instance: NDArray[np.int32]
    class_id: NDArray[np.int16]
    part_id: NDArray[np.int16]
    intensity: NDArray[np.uint8] | None
    face: NDArray[np.int32]
    position: Vec3
    orientation: Quat
    stamp: float
    camera: CameraModel
    odometry_position: Vec3 = field(default=None)  # type: ignore[arg-type]
    odometry_orientation: Quat = field(default=None)  # type: ignore[arg-type]
    rgb: NDArray[np.uint8] | None = None

    def __post_init__(self) -> None:
        if self.odometry_position is None:
            self.odometry_position = self.position
        if self.odometry_orientation is None:
            self.odometry_orientation = self.orientation

    @property
    def shape(self) -> tuple[int, int]:
        return self.depth.shape  # type: ignore[return-value]

    def grey(self) -> NDArray[np.uint8]:
        """The intensity image; a clear error for a frame rendered without one."""
        if self.intensity is None:
            raise InvalidInputError(
                "this frame was rendered without its intensity image (render(..., intensity=False))"
            )
        return self.intensity

    def points(self, mask: ArrayLike | None = None, use_odometry: bool = False) -> NDArray:
        """World points ``(N, 3)`` of the pixels in ``mask`` that saw a surface (row-major).

        With ``use_odometry`` the points are placed from the odometry pose, as a robot whose
        estimate is off (drift, image/odometry desync) would place them.
        """
        valid = np.isfinite(self.depth)
        if mask is not None:
            chosen = np.asarray(mask, dtype=bool)
            if chosen.shape != self.shape:
                raise InvalidInputError(f"mask shape {chosen.shape} != frame shape {self.shape}")
            valid &= chosen
        return self._placed(np.flatnonzero(valid), use_odometry)

    def pixel_points(self, pixels: ArrayLike, use_odometry: bool = False) -> NDArray:
        """World points ``(N, 3)`` of the row-major pixel indices ``pixels`` that saw a surface.

        The points of ``points(mask)`` when ``pixels`` are the mask's indices in order, without
        a pass over the whole frame: what a caller that knows a small mask's pixels wants.
        """
        flat = np.asarray(pixels, dtype=np.intp).reshape(-1)
        if flat.size and (flat.min() < 0 or flat.max() >= self.depth.size):
            raise InvalidInputError(f"pixel indices must lie in [0, {self.depth.size})")
        return self._placed(flat, use_odometry)

    def _placed(self, flat: NDArray[np.intp], use_odometry: bool) -> NDArray:
        """World points of the pixels ``flat`` that have a finite depth."""
        directions, cosine = self.camera.rays
        depth = self.depth.reshape(-1)
        # The dtypes numpy gives depth / cosine and directions * that, as before this kernel.
        scale = np.empty(len(flat), np.result_type(depth, cosine))
        body = np.empty((len(flat), 3), np.result_type(directions, scale))
        hits = _hit_rays(depth, cosine, directions, flat, scale, body)
        position, orientation = (
            (self.odometry_position, self.odometry_orientation)
            if use_odometry
            else (self.position, self.orientation)
        )
        points = rotate_rows(body[:hits], Rotation.from_quat(orientation).as_matrix())
        points += position  # in place: the same sums without another array
        return points


@numba.njit(cache=True)
def _hit_rays(depth, cosine, directions, flat, scale, body):  # noqa: PLR0917 - a compiled kernel
    """Body-frame points ``directions * depth / cosine`` of the pixels ``flat`` whose depth is
    finite, in order, into ``body``; returns how many.

    Each quotient is stored (rounded to ``scale``'s dtype) before it multiplies, as in the
    numpy expression ``directions[flat] * (depth[flat] / cosine[flat])[:, None]``.
    """
    hits = 0
    for pixel in flat:
        if np.isfinite(depth[pixel]):
            scale[hits] = depth[pixel] / cosine[pixel]
            for axis in range(3):
                body[hits, axis] = directions[pixel, axis] * scale[hits]
            hits += 1
    return hits


def render(
    world: World,
    camera: CameraModel,
    position: ArrayLike,
    orientation: ArrayLike,
    *,
    noise: NoiseModel | None = None,
    rng: np.random.Generator | NormalStream | None = None,
    stamp: float = 0.0,
    stride: int = 1,
    odometry: tuple[ArrayLike, ArrayLike] | None = None,
    threads: int = 1,
    intensity: bool = True,
    appearance: Appearance | None = None,
) -> Frame:
    """Render a frame of ``world`` from the camera pose ``(position, orientation [x,y,z,w])``.

    Args:
        noise: depth and intensity noise (``None``: ideal).
        rng: generator for the noise, required when the noise model is not ideal; or a
            :class:`NormalStream` of its deviates drawn ahead (the same frame).
        stamp: time the frame is tagged with.
        stride: render every ``stride``-th pixel (see :meth:`CameraModel.scaled`).
        odometry: the ``(position, orientation)`` the robot believed it had at ``stamp``.
        threads: cast the rays on this many threads (the same frame on any number).
        intensity: shade the intensity image; False leaves it out (``Frame.intensity`` None)
            for a caller that reads only depth and labels. The noise draws the same deviates
            either way, so a seeded run's depth noise does not depend on it.
        appearance: also render the colour image under it (``Frame.rgb``, ideal: its noise
            is the caller's, :func:`~seminspect.sensors.appearance.add_colour_noise`); the
            other images and the noise draws are the same with or without it.
    """
    origin = as_point(position, "camera position")
    quat = as_quaternion(orientation, "camera orientation")
    model = camera.scaled(stride)
    directions, distance, face = _cast_rays(world, model, origin, quat, threads)
    depth, instance, class_id, part_id, grey = _shade_pixels(
        world, model, origin, (directions, distance, face), threads=threads, intensity=intensity
    )
    shape = (model.height, model.width)
    colour = (
        None
        if appearance is None
        else colour_image(appearance, world, origin, (directions, distance, face), 1.0 / model.fx)
    )
    frame = Frame(
        depth=depth.reshape(shape),
        instance=instance.reshape(shape),
        class_id=class_id.reshape(shape),
        part_id=part_id.reshape(shape),
        intensity=None if grey is None else grey.reshape(shape),
        face=face.reshape(shape),
        position=origin,
        orientation=quat,
        stamp=float(stamp),
        camera=model,
        odometry_position=origin
        if odometry is None
        else as_point(odometry[0], "odometry position"),
        odometry_orientation=quat
        if odometry is None
        else as_quaternion(odometry[1], "odometry orientation"),
        rgb=None if colour is None else colour.reshape((*shape, 3)),
    )
    if noise is not None and not noise.is_ideal:
        _add_image_noise(frame, noise, rng if isinstance(rng, NormalStream) else require_rng(rng))
    return frame


#: Per pixel (row-major): the ray's world-frame direction, the distance to what it hits and
#: that face's index (-1: nothing within range).
_Hits = tuple[NDArray[np.float32], NDArray[np.float32], NDArray[np.int32]]


def _cast_rays(world: World, model: CameraModel, origin: Vec3, quat: Quat, threads: int) -> _Hits:
    """Cast every pixel's ray from the camera pose ``(origin, quat)``."""
    directions_body, cosine = model.rays
    count = len(cosine)
    directions, distance = _scratch(count)
    rotation = Rotation.from_quat(quat).as_matrix().astype(np.float32)
    rotate_rows(directions_body, rotation, out=directions, threads=threads)
    distance, face = world.raycaster.cast(
        origin,
        directions,
        model.ray_limits,
        threads,
        out=(distance, np.empty(count, dtype=np.int32)),
    )
    return directions, distance, face


def _shade_pixels(
    world: World,
    model: CameraModel,
    origin: Vec3,
    hits: _Hits,
    *,
    threads: int,
    intensity: bool,
) -> tuple[
    NDArray[np.float32],
    NDArray[np.int32],
    NDArray[np.int16],
    NDArray[np.int16],
    NDArray[np.uint8] | None,
]:
    """The flat depth, instance, class, part and (with ``intensity``) grey images of the hits."""
    directions, distance, face = hits
    cosine = model.rays[1]
    count = len(cosine)
    depth = np.empty(count, dtype=np.float32)
    instance = np.empty(count, dtype=np.int32)
    class_id = np.empty(count, dtype=np.int16)
    part_id = np.empty(count, dtype=np.int16)
    grey = np.empty(count if intensity else 0, dtype=np.uint8)
    albedo, axes, seed, sun = surface_tables(world)

    def shade(part: slice) -> None:
        shade_hits(
            distance[part],
            face[part],
            directions[part],
            cosine[part],
            origin,
            1.0 / model.fx,
            world.face_instance,
            world.face_class,
            world.face_part,
            albedo,
            axes,
            seed,
            sun,
            OCTAVES,
            OCTAVE_WEIGHTS,
            depth[part],
            instance[part],
            class_id[part],
            part_id[part],
            grey[part] if intensity else grey,
        )

    # Pixels shade independently, so they may be dealt out over threads.
    run_dealt(shade, count, threads, MIN_PIXELS_PER_THREAD)
    return depth, instance, class_id, part_id, grey if intensity else None


_SCRATCH = threading.local()
#: Below this many pixels per thread, splitting the shading costs more than it saves.
MIN_PIXELS_PER_THREAD = 8192
#: The dtype of the image noise draw, by ``NoiseModel.image_noise_float32``.
_DRAW_DTYPE: dict[bool, type[np.float32] | type[np.float64]] = {False: np.float64, True: np.float32}


def _scratch(count: int) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """This thread's ray directions ``(count, 3)`` and distances, reused from frame to frame.

    Neither leaves :func:`render` (a frame keeps its own arrays), so one pair per thread and
    ray count saves allocating and faulting in 5 MB per 640 x 480 frame.
    """
    if not hasattr(_SCRATCH, "by_count"):
        _SCRATCH.by_count = {}
    buffers = _SCRATCH.by_count.get(count)
    if buffers is None:
        buffers = (np.empty((count, 3), np.float32), np.empty(count, np.float32))
        _SCRATCH.by_count[count] = buffers
    return buffers


def _add_image_noise(
    frame: Frame, noise: NoiseModel, rng: np.random.Generator | NormalStream
) -> None:
    """Depth noise with a range-dependent sigma, and pixel noise on the intensity image.

    All the normal deviates come from one draw: the hit pixels' depth noise first (row-major),
    then one per intensity pixel, the same numbers in the same order as two separate draws.
    ``noise.image_noise_float32`` draws them in single precision (a faster draw, and other
    numbers). A frame without its intensity image draws the intensity's deviates all the same
    and leaves them unused, so the next frame's noise is the same either way.
    """
    depth = frame.depth.reshape(-1)  # views: render's images are contiguous
    noisy_depth = bool(noise.depth_noise_m or noise.depth_noise_per_m)
    hits = int(np.count_nonzero(np.isfinite(depth))) if noisy_depth else 0
    pixels = depth.size if noise.intensity_noise else 0
    grey = np.empty(0, np.uint8) if frame.intensity is None else frame.intensity.reshape(-1)
    _apply_image_noise(
        depth,
        grey,
        rng.standard_normal(hits + pixels, dtype=_DRAW_DTYPE[noise.image_noise_float32]),
        hits > 0,
        np.float32(noise.depth_noise_m),
        np.float32(noise.depth_noise_per_m),
        float(noise.intensity_noise),
    )


@numba.njit(cache=True)
def _apply_image_noise(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    depth: np.ndarray,
    intensity: np.ndarray,
    normals: np.ndarray,
    noisy_depth: bool,
    sigma_0: np.float32,
    sigma_per_m: np.float32,
    intensity_sigma: float,
) -> None:
    """Add ``normals`` to the flat depth (hits only) and intensity images, in place.

    The arithmetic is float32 for depth and float64 for intensity, as the numpy expressions it
    replaces were (``tests/sensors/test_camera.py`` holds them as the reference).
    """
    k = 0
    if noisy_depth:
        floor = np.float32(1e-3)
        for i in range(depth.shape[0]):
            if np.isfinite(depth[i]):
                sigma = sigma_0 + sigma_per_m * depth[i]
                depth[i] = max(depth[i] + np.float32(normals[k]) * sigma, floor)
                k += 1
    if intensity_sigma:
        for i in range(intensity.shape[0]):
            value = intensity[i] + intensity_sigma * normals[k]
            intensity[i] = np.uint8(min(max(value, 0.0), 255.0))
            k += 1
