"""The semantic inspection environment of 004 as a Gymnasium vector environment.

Many rooms (:mod:`seminspect.missions.learning.rooms`) are stepped together: every room sits in one
Embree scene, shifted along x, so one call casts the camera and LiDAR rays of all of them. The
robot's maps are numpy arrays updated in place.

Per step (10 Hz, the paper's image rate):

- The action a_t in [-1, 1]^4 is scaled by w_max (004 eq (5)) into a body-frame velocity and yaw
  rate command. A first-order velocity loop (time constant ``velocity_time_constant``) tracks
  it, integrated in closed form over the step, with a random disturbance acceleration
  (004 Sec III-E). The vehicle stays level: orientation is yaw only.
- The camera (87 x 58 deg, 96 x 54 pixels) and a 360 x 90 deg LiDAR are cast; their noisy ranges
  (standard deviation growing linearly with range, Sec III-E) mark occupied cells of the robot's
  own 0.1 m map (range data only, Sec III-A).
- Observation eq (4): state s_t (eq (1)) with uniform noise, the previous action, the masked
  depth D_t∘S_t, the ego-centric occupancy map m^o and the spatial visit score map m^h (eq (3)),
  both 21^3 at 0.1 m in the yaw-aligned body frame.
- Reward eq (6): face-mesh reward f_t (eqs (7)-(9)), semantic-search reward v_t (eq (10)) and the
  collision penalty p_t (-1 when an occupied cell of m^o lies within d_coll). Contact (true
  clearance below the robot radius) is a crash and ends the episode; reaching the episode
  length without one is a timeout (Sec IV-A).

The state vector (17 values): position relative to the room centre divided by the half size,
quaternion (w, x, y, z), body-frame linear velocity (m/s), angular velocity (rad/s), then the
previous action. The paper states velocities in the inertial frame; body-frame velocities keep
the whole observation ego-centric like the maps, which the policy then need not rotate.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numba
import numpy as np
from gymnasium.vector import AutoresetMode
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, model_validator

from seminspect.core.errors import InvalidInputError
from seminspect.core.rng import make_rng
from seminspect.missions.learning.rooms import (
    TARGET_FACES,
    Room,
    clearance,
    sample_room,
    stack_solids,
)
from seminspect.worlds.raycast import RayCaster

STATE_SIZE = 17
ACTION_SIZE = 4
#: Gap between neighbouring rooms in the shared ray-casting scene (metres).
ROOM_GAP = 2.0


class EnvConfig(BaseModel):
    """Parameters of the environment; defaults follow 004 where it gives a value."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    obstacles: int = Field(9, ge=0, le=60, description="obstacles per room (Table I: 0-19)")
    room_size: tuple[float, float, float] = (10.0, 10.0, 4.0)
    episode_seconds: float = Field(90.0, gt=0.0, description="004 Sec III-E: 90 s")
    control_hz: float = Field(10.0, gt=0.0, description="image rate, 004 Sec III-E")
    image_size: tuple[int, int] = (96, 54)
    fov_deg: tuple[float, float] = (87.0, 58.0)
    camera_range: float = Field(10.0, gt=0.0)
    lidar_beams: tuple[int, int] = (32, 8)
    map_cells: int = Field(21, ge=3, description="n of the n^3 ego maps (004: 21)")
    map_resolution: float = Field(0.1, gt=0.0, description="r_V (004: 0.1 m)")
    max_speed: float = Field(1.0, gt=0.0, description="w_max linear (004: 1 m/s)")
    max_yaw_rate: float = Field(1.0, gt=0.0, description="w_max yaw (004: 1 rad/s)")
    velocity_time_constant: float = Field(0.2, gt=0.0)
    disturbance_std: float = Field(0.3, ge=0.0, description="m/s^2, redrawn every step")
    state_noise: float = Field(0.02, ge=0.0, description="uniform half-width, SI units")
    depth_noise: tuple[float, float] = (0.005, 0.01)  # sigma = a + b * range
    d_ref: float = Field(1.5, gt=0.0, description="reference inspection distance (004: 0.5-2.5)")
    inspect_range: float = Field(3.0, gt=0.0, description="a face counts as covered within it")
    alpha: float = Field(0.15, gt=0.0, description="eq (7) gain")
    beta: float = Field(1.0, gt=0.0, description="eq (7) distance fall-off")
    gamma: float = Field(0.005, ge=0.0, description="eq (10) gain")
    delta: float = Field(0.02, ge=0.0, description="eq (10) fall-off per visit")
    d_coll: float = Field(0.3, gt=0.0, description="collision distance (004: 0.3 m)")
    robot_radius: float = Field(0.2, gt=0.0)
    crash_penalty: float = Field(5.0, ge=0.0, description="extra penalty when a crash ends")
    use_svs: bool = Field(True, description="False: m^h is all zeros (Table II)")

    @model_validator(mode="after")
    def _consistent(self) -> EnvConfig:
        if self.map_cells % 2 == 0:
            raise ValueError("map_cells must be odd so the robot sits in the centre cell")
        if min(self.room_size) <= 0 or min(self.image_size) <= 0 or min(self.lidar_beams) <= 0:
            raise ValueError("room, image and LiDAR sizes must be positive")
        if self.robot_radius > self.d_coll:
            raise ValueError("robot_radius must not exceed d_coll")
        return self

    @property
    def steps_per_episode(self) -> int:
        return round(self.episode_seconds * self.control_hz)


def _camera_rays(config: EnvConfig) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """Body-frame unit rays of the pinhole camera (x forward, y left, z up) and their cosines."""
    width, height = config.image_size
    h_fov, v_fov = np.radians(config.fov_deg)
    u = (np.arange(width) + 0.5) / width * 2.0 - 1.0
    v = (np.arange(height) + 0.5) / height * 2.0 - 1.0
    uu, vv = np.meshgrid(u, v)
    rays = np.stack(
        [np.ones_like(uu), -uu * math.tan(h_fov / 2), -vv * math.tan(v_fov / 2)], axis=-1
    ).reshape(-1, 3)
    rays /= np.linalg.norm(rays, axis=1, keepdims=True)
    return rays.astype(np.float32), rays[:, 0].astype(np.float32)


def _lidar_rays(config: EnvConfig) -> NDArray[np.float32]:
    """Body-frame unit rays of a 360 x 90 deg LiDAR."""
    n_az, n_el = config.lidar_beams
    az = np.linspace(-math.pi, math.pi, n_az, endpoint=False)
    el = np.radians(np.linspace(-45.0, 45.0, n_el))
    aa, ee = np.meshgrid(az, el)
    rays = np.stack([np.cos(ee) * np.cos(aa), np.cos(ee) * np.sin(aa), np.sin(ee)], axis=-1)
    return rays.reshape(-1, 3).astype(np.float32)


def _focus_mask(config: EnvConfig) -> NDArray[np.bool_]:
    """Central half of the image in each dimension: the focus area of 004 Sec III-C."""
    width, height = config.image_size
    cols = np.abs(np.arange(width) + 0.5 - width / 2) < width / 4
    rows = np.abs(np.arange(height) + 0.5 - height / 2) < height / 4
    return (rows[:, None] & cols[None, :]).reshape(-1)


def _mapping_pixels(config: EnvConfig) -> NDArray[np.bool_]:
    """Every third pixel in each direction: the camera returns that feed the map.

    At the ego map's reach (about 1 m) their spacing is about 6 cm, finer than its 0.1 m cells.
    """
    width, height = config.image_size
    rows, cols = np.arange(height) % 3 == 1, np.arange(width) % 3 == 1
    return (rows[:, None] & cols[None, :]).reshape(-1)


def _ego_offsets(config: EnvConfig) -> NDArray[np.float64]:
    """Body-frame centres of the n^3 ego-map cells, x fastest-varying last (D, H, W = z, y, x)."""
    half = config.map_cells // 2
    steps = (np.arange(config.map_cells) - half) * config.map_resolution
    zz, yy, xx = np.meshgrid(steps, steps, steps, indexing="ij")
    return np.stack([xx, yy, zz], axis=-1).reshape(-1, 3)


@numba.njit(cache=True)
def _hits_upright_cylinder(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    ox: float,
    oy: float,
    oz: float,
    dx: float,
    dy: float,
    dz: float,
    cx: float,
    cy: float,
    cz: float,
    radius: float,
    half: float,
    reach: float,
) -> bool:
    """Whether a ray meets an upright cylinder within ``reach`` (a conservative bound test)."""
    t_low, t_high = 0.0, reach
    if abs(dz) < 1e-12:
        if abs(oz - cz) > half:
            return False
    else:
        t1, t2 = (cz - half - oz) / dz, (cz + half - oz) / dz
        t_low, t_high = max(t_low, min(t1, t2)), min(t_high, max(t1, t2))
    px, py = ox - cx, oy - cy
    a = dx * dx + dy * dy
    b = px * dx + py * dy
    c = px * px + py * py - radius * radius
    if a < 1e-12:
        return c <= 0.0 and t_low <= t_high
    disc = b * b - a * c
    if disc < 0.0:
        return False
    root = math.sqrt(disc)
    return max(t_low, (-b - root) / a) <= min(t_high, (-b + root) / a)


@numba.njit(cache=True)
def _sensor_rays(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    origin: NDArray[np.float64],
    yaw: NDArray[np.float64],
    camera: NDArray[np.float32],
    lidar: NDArray[np.float32],
    mapped: NDArray[np.bool_],
    target_centre: NDArray[np.float64],
    target_size: NDArray[np.float64],
    reach: float,
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float32], NDArray[np.float32]]:
    """The rays each room needs, grouped by room: (row, ray id, origin, direction).

    Camera pixels are cast when they may see the target (their ray meets its bounding
    cylinder) or when they belong to the mapping subset ``mapped``; every LiDAR beam is cast.
    A pixel left out can only see something other than the target, so the masked depth and
    the face reward are exact; only the map takes fewer (coarser) camera returns.
    """
    n_cam, n_lidar = camera.shape[0], lidar.shape[0]
    per_room = n_cam + n_lidar
    rows = np.empty(origin.shape[0] * per_room, dtype=np.int64)
    ids = np.empty_like(rows)
    count = 0
    for r in range(origin.shape[0]):
        c, s = math.cos(yaw[r]), math.sin(yaw[r])
        tc, tr, th = target_centre[r], target_size[r, 0] + 1e-3, target_size[r, 1] + 1e-3
        for k in range(n_cam):
            keep = mapped[k]
            if not keep:
                dx = c * camera[k, 0] - s * camera[k, 1]
                dy = s * camera[k, 0] + c * camera[k, 1]
                keep = _hits_upright_cylinder(
                    origin[r, 0],
                    origin[r, 1],
                    origin[r, 2],
                    dx,
                    dy,
                    camera[k, 2],
                    tc[0],
                    tc[1],
                    tc[2],
                    tr,
                    th,
                    reach,
                )
            if keep:
                rows[count], ids[count] = r, k
                count += 1
        for k in range(n_lidar):
            rows[count], ids[count] = r, n_cam + k
            count += 1
    starts = np.empty((count, 3), dtype=np.float32)
    dirs = np.empty((count, 3), dtype=np.float32)
    for i in range(count):
        r, k = rows[i], ids[i]
        body = camera[k] if k < n_cam else lidar[k - n_cam]
        c, s = math.cos(yaw[r]), math.sin(yaw[r])
        dirs[i, 0] = c * body[0] - s * body[1]
        dirs[i, 1] = s * body[0] + c * body[1]
        dirs[i, 2] = body[2]
        starts[i, 0], starts[i, 1], starts[i, 2] = origin[r, 0], origin[r, 1], origin[r, 2]
    return rows[:count], ids[:count], starts, dirs


@numba.njit(cache=True)
def _mark_hits(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    occupancy: NDArray[np.uint8],
    env_of_ray: NDArray[np.int64],
    starts: NDArray[np.float32],
    dirs: NDArray[np.float32],
    distance: NDArray[np.float64],
    room_shift: NDArray[np.float64],
    row: NDArray[np.int64],
    resolution: float,
) -> None:
    """Mark the cell of every ranged return as occupied in its robot's own map (Sec III-A)."""
    nz, ny, nx = occupancy.shape[1], occupancy.shape[2], occupancy.shape[3]
    for i in range(distance.shape[0]):
        d = distance[i]
        if not math.isfinite(d):
            continue
        shift = room_shift[row[i]]
        x = starts[i, 0] - shift[0] + dirs[i, 0] * d
        y = starts[i, 1] - shift[1] + dirs[i, 1] * d
        z = starts[i, 2] - shift[2] + dirs[i, 2] * d
        a = min(max(math.floor(x / resolution), 0), nx - 1)
        b = min(max(math.floor(y / resolution), 0), ny - 1)
        m = min(max(math.floor(z / resolution), 0), nz - 1)
        occupancy[env_of_ray[i], m, b, a] = 1


@numba.njit(cache=True)
def _gather_ego(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    occupancy: NDArray[np.uint8],
    visits: NDArray[np.uint16],
    rows: NDArray[np.int64],
    position: NDArray[np.float64],
    yaw: NDArray[np.float64],
    offsets: NDArray[np.float64],
    resolution: float,
    out_occupancy: NDArray[np.float32],
    out_visits: NDArray[np.float32],
) -> None:
    """Sample the robots' world-frame maps at the yaw-rotated ego cells (outside: occupied)."""
    nz, ny, nx = occupancy.shape[1], occupancy.shape[2], occupancy.shape[3]
    for r in range(rows.shape[0]):
        env = rows[r]
        c, s = math.cos(yaw[r]), math.sin(yaw[r])
        px, py, pz = position[r, 0], position[r, 1], position[r, 2]
        for k in range(offsets.shape[0]):
            ox, oy, oz = offsets[k, 0], offsets[k, 1], offsets[k, 2]
            i = math.floor((px + c * ox - s * oy) / resolution)
            j = math.floor((py + s * ox + c * oy) / resolution)
            m = math.floor((pz + oz) / resolution)
            if 0 <= i < nx and 0 <= j < ny and 0 <= m < nz:
                out_occupancy[r, k] = occupancy[env, m, j, i]
                out_visits[r, k] = visits[env, m, j, i]
            else:
                out_occupancy[r, k] = 1.0
                out_visits[r, k] = 0.0


@numba.njit(cache=True)
def _entropy_in_place(counts: NDArray[np.float32], totals: NDArray[np.float64]) -> None:
    """Rows of visit counts -> -p log p with p = count / row total (eq (3)); totals out."""
    for r in range(counts.shape[0]):
        total = 0.0
        for k in range(counts.shape[1]):
            total += counts[r, k]
        totals[r] = total
        if total <= 0.0:
            continue
        for k in range(counts.shape[1]):
            if counts[r, k] > 0.0:
                p = counts[r, k] / total
                counts[r, k] = -p * math.log(p)


def spatial_visit_scores(counts: NDArray) -> tuple[NDArray[np.float32], NDArray[np.float64]]:
    """004 eq (3): m^h = -p log p, p the visits of a cell over the local total N_t.

    ``counts`` is ``(rows, cells)``; returns the scores and N_t of each row.
    """
    scores = np.array(counts, dtype=np.float32, copy=True)
    totals = np.empty(len(scores))
    _entropy_in_place(scores, totals)
    return scores, totals


def world_from_body(vectors: NDArray, yaw: NDArray) -> NDArray[np.float64]:
    """Rows of body-frame vectors in the world frame of a level vehicle with heading ``yaw``."""
    c, s = np.cos(yaw), np.sin(yaw)
    x, y = vectors[:, 0], vectors[:, 1]
    return np.stack([c * x - s * y, s * x + c * y, vectors[:, 2]], 1)


def body_from_world(vectors: NDArray, yaw: NDArray) -> NDArray[np.float64]:
    """Rows of world-frame vectors in the body frame of a level vehicle with heading ``yaw``."""
    c, s = np.cos(yaw), np.sin(yaw)
    x, y = vectors[:, 0], vectors[:, 1]
    return np.stack([c * x + s * y, -s * x + c * y, vectors[:, 2]], 1)


def face_scores(
    distance: NDArray[np.float64],
    best: NDArray[np.float64],
    d_ref: float,
    alpha: float,
    beta: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """004 eqs (7)-(8): per-face inspection scores n_f and the updated best distances d_f.

    ``distance`` holds this step's mean camera-face distance (nan for faces not in view);
    ``best`` the stored d_f (inf before the first view).
    """
    seen = np.isfinite(distance)
    closer = seen & (np.abs(np.where(seen, distance, 0.0) - d_ref) < np.abs(best - d_ref))
    scores = np.where(
        closer, alpha * np.exp(-beta * (np.where(seen, distance, 0.0) - d_ref) ** 2), 0.0
    )
    return scores, np.where(scores > 0, distance, best)


def semantic_search_reward(visits: NDArray, gamma: float, delta: float) -> NDArray[np.float64]:
    """004 eq (10): v_t = gamma exp(-delta N_t)."""
    return gamma * np.exp(-delta * np.asarray(visits, dtype=np.float64))


class InspectionVectorEnv(gym.vector.VectorEnv):
    """``num_envs`` rooms stepped together (SAME_STEP autoreset unless ``autoreset=False``).

    Without autoreset a finished room is frozen (zero reward, unchanged observation) until the
    next :meth:`reset`, which suits evaluation: every room runs exactly one episode.
    """

    metadata = {"autoreset_mode": AutoresetMode.SAME_STEP}  # noqa: RUF012 - gymnasium API

    def __init__(
        self,
        num_envs: int,
        config: EnvConfig | None = None,
        *,
        seed: int = 0,
        autoreset: bool = True,
        record: bool = False,
        threads: int = 1,
    ) -> None:
        if num_envs < 1:
            raise InvalidInputError(f"num_envs must be >= 1, got {num_envs}")
        self.config = config or EnvConfig()
        self.num_envs = num_envs
        self.autoreset = autoreset
        self.record = record
        self.threads = threads
        self._seed = seed
        self._obstacles = np.full(num_envs, self.config.obstacles, dtype=np.int64)
        self._build_spaces()
        self._build_sensors()
        self._allocate()

    # -- set-up -------------------------------------------------------------------------------

    def _build_spaces(self) -> None:
        width, height = self.config.image_size
        n = self.config.map_cells
        single = gym.spaces.Dict(
            {
                "state": gym.spaces.Box(-np.inf, np.inf, (STATE_SIZE,), np.float32),
                "depth": gym.spaces.Box(0.0, 1.0, (1, height, width), np.float32),
                "maps": gym.spaces.Box(0.0, 1.0, (2, n, n, n), np.float32),
            }
        )
        self.single_observation_space = single
        self.single_action_space = gym.spaces.Box(-1.0, 1.0, (ACTION_SIZE,), np.float32)
        self.observation_space = gym.vector.utils.batch_space(single, self.num_envs)
        self.action_space = gym.vector.utils.batch_space(self.single_action_space, self.num_envs)

    def _build_sensors(self) -> None:
        self._camera, self._camera_cos = _camera_rays(self.config)
        self._lidar = _lidar_rays(self.config)
        self._focus = _focus_mask(self.config)
        self._mapped = _mapping_pixels(self.config)
        self._offsets = _ego_offsets(self.config)
        self._near = np.linalg.norm(self._offsets, axis=1) <= self.config.d_coll
        self._spacing = self.config.room_size[0] + ROOM_GAP

    def _allocate(self) -> None:
        count, cfg = self.num_envs, self.config
        cells = np.ceil(np.asarray(cfg.room_size) / cfg.map_resolution).astype(int)
        # z, y, x order: the ego cells are walked x-fastest, so lookups stay close in memory.
        self._occupancy = np.zeros((count, *cells[::-1]), dtype=np.uint8)
        self._visits = np.zeros((count, *cells[::-1]), dtype=np.uint16)
        self._position = np.zeros((count, 3))
        self._velocity = np.zeros((count, 3))
        self._yaw = np.zeros(count)
        self._yaw_rate = np.zeros(count)
        self._previous_action = np.zeros((count, ACTION_SIZE), dtype=np.float32)
        self._best = np.full((count, TARGET_FACES), np.inf)
        self._steps = np.zeros(count, dtype=np.int64)
        self._return = np.zeros(count)
        self._done = np.zeros(count, dtype=bool)
        self._rngs = [make_rng(self._seed, "learning", f"env-{i}") for i in range(count)]
        self._rooms: list[Room] = []
        self._caster: RayCaster | None = None
        width, height = cfg.image_size
        n = cfg.map_cells
        self._obs = {
            "state": np.zeros((count, STATE_SIZE), dtype=np.float32),
            "depth": np.zeros((count, 1, height, width), dtype=np.float32),
            "maps": np.zeros((count, 2, n, n, n), dtype=np.float32),
        }
        self._tracks: list[list[NDArray[np.float64]]] = [[] for _ in range(count)]

    # -- public API ---------------------------------------------------------------------------

    def set_obstacles(self, counts: int | Sequence[int]) -> None:
        """Obstacle counts used from each room's next reset (the training curriculum)."""
        values = np.broadcast_to(np.asarray(counts, dtype=np.int64), (self.num_envs,))
        if np.any(values < 0):
            raise InvalidInputError("obstacle counts must be >= 0")
        self._obstacles = values.copy()

    @property
    def rooms(self) -> list[Room]:
        """The room each environment is in now."""
        return list(self._rooms)

    def coverage(self) -> NDArray[np.float64]:
        """Fraction of each room's target faces inspected within ``inspect_range`` so far."""
        return (self._best <= self.config.inspect_range).mean(axis=1)

    def positions(self) -> NDArray[np.float64]:
        """True ``(num_envs, 3)`` robot positions in room coordinates (for baselines, pictures)."""
        return self._position.copy()

    def yaws(self) -> NDArray[np.float64]:
        """True robot headings (rad)."""
        return self._yaw.copy()

    def face_distances(self, env: int) -> NDArray[np.float64]:
        """Best viewing distance d_f of each target face of one room (inf: never seen)."""
        return self._best[env].copy()

    def track(self, env: int) -> NDArray[np.float64]:
        """Recorded ``(T, 5)`` rows (x, y, z, yaw, coverage) of one room's episode."""
        if not self.record:
            raise InvalidInputError("tracks are kept only with record=True")
        return np.array(self._tracks[env]).reshape(-1, 5)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, NDArray[np.float32]], dict[str, Any]]:
        if seed is not None:
            self._seed = seed
            self._rngs = [make_rng(seed, "learning", f"env-{i}") for i in range(self.num_envs)]
        if options and "obstacles" in options:
            self.set_obstacles(options["obstacles"])
        self._rooms = [self._sample_room(i) for i in range(self.num_envs)]
        every = np.arange(self.num_envs)
        self._begin(every)
        self._rebuild_scene()
        self._sense(every)
        return self._copy_obs(), {"coverage": self.coverage()}

    def step(
        self, actions: NDArray
    ) -> tuple[dict[str, NDArray[np.float32]], NDArray, NDArray, NDArray, dict[str, Any]]:
        if self._caster is None:
            raise InvalidInputError("call reset() before step()")
        act = np.asarray(actions, dtype=np.float32).reshape(self.num_envs, ACTION_SIZE)
        if not np.all(np.isfinite(act)):
            raise InvalidInputError("actions must be finite")
        act = np.clip(act, -1.0, 1.0)
        live = np.flatnonzero(~self._done)
        reward = np.zeros(self.num_envs)
        crash = np.zeros(self.num_envs, dtype=bool)
        if len(live):  # without autoreset every room may have ended already
            self._move(live, act)
            self._steps[live] += 1
            reward[live] = self._sense(live)
            crash[live] = self._crashed(live)
        reward[crash] -= self.config.crash_penalty
        timeout = ~crash & (self._steps >= self.config.steps_per_episode)
        timeout &= ~self._done
        self._return += reward
        ended = crash | timeout
        info: dict[str, Any] = {"coverage": self.coverage()}
        if ended.any():
            info["episode"] = {
                "coverage": self.coverage(),
                "crash": crash.copy(),
                "timeout": timeout.copy(),
                "return": self._return.copy(),
                "length": self._steps.copy(),
            }
            info["_episode"] = ended.copy()
        self._done |= ended
        obs = self._copy_obs()
        if self.autoreset and ended.any():
            info["final_obs"] = obs
            info["_final_obs"] = ended.copy()
            obs = self._restart(np.flatnonzero(ended))
        return obs, reward.astype(np.float32), crash, timeout, info

    # -- episode bookkeeping -------------------------------------------------------------------

    def _sample_room(self, env: int) -> Room:
        return sample_room(self._rngs[env], int(self._obstacles[env]), self.config.room_size)

    def _begin(self, envs: NDArray[np.int64]) -> None:
        for env in envs:
            room = self._rooms[env]
            self._position[env] = room.start
            self._yaw[env] = room.start_yaw
            self._tracks[env] = []
        self._velocity[envs] = 0.0
        self._yaw_rate[envs] = 0.0
        self._previous_action[envs] = 0.0
        self._occupancy[envs] = 0
        self._visits[envs] = 0
        self._best[envs] = np.inf
        self._steps[envs] = 0
        self._return[envs] = 0.0
        self._done[envs] = False
        self._solids = stack_solids(self._rooms) if self._rooms else None

    def _restart(self, envs: NDArray[np.int64]) -> dict[str, NDArray[np.float32]]:
        for env in envs:
            self._rooms[env] = self._sample_room(int(env))
        self._begin(envs)
        self._rebuild_scene()
        self._sense(envs)
        return self._copy_obs()

    def _rebuild_scene(self) -> None:
        """One Embree scene holding every room, room ``i`` shifted by ``i * spacing`` along x."""
        vertices, triangles, faces, base = [], [], [], 0
        for i, room in enumerate(self._rooms):
            vertices.append(room.vertices + np.array([i * self._spacing, 0.0, 0.0]))
            triangles.append(room.triangles + base)
            faces.append(room.face_of_triangle)
            base += len(room.vertices)
        self._caster = RayCaster(np.vstack(vertices), np.vstack(triangles))
        self._face_of_triangle = np.concatenate(faces)

    def _copy_obs(self) -> dict[str, NDArray[np.float32]]:
        return {key: value.copy() for key, value in self._obs.items()}

    # -- dynamics --------------------------------------------------------------------------------

    def _move(self, envs: NDArray[np.int64], action: NDArray[np.float32]) -> None:
        """Exact first-order velocity response over one step, with a disturbance (eq (5))."""
        cfg = self.config
        dt, tau = 1.0 / cfg.control_hz, cfg.velocity_time_constant
        decay = math.exp(-dt / tau)
        a = action[envs].astype(np.float64)
        command = world_from_body(a[:, :3] * cfg.max_speed, self._yaw[envs])
        push = np.stack([self._rngs[e].normal(0.0, cfg.disturbance_std, 3) for e in envs])
        command += push * tau
        v = self._velocity[envs]
        self._position[envs] += command * dt + (v - command) * tau * (1.0 - decay)
        self._velocity[envs] = command + (v - command) * decay
        yaw_command = a[:, 3] * cfg.max_yaw_rate
        w = self._yaw_rate[envs]
        self._yaw[envs] += yaw_command * dt + (w - yaw_command) * tau * (1.0 - decay)
        self._yaw[envs] = (self._yaw[envs] + math.pi) % (2.0 * math.pi) - math.pi
        self._yaw_rate[envs] = yaw_command + (w - yaw_command) * decay
        self._previous_action[envs] = action[envs]

    def _crashed(self, envs: NDArray[np.int64]) -> NDArray[np.bool_]:
        solids = self._solids
        assert solids is not None
        subset = type(solids)(
            solids.kind[envs], solids.centre[envs], solids.rotation[envs], solids.size[envs]
        )
        gap = clearance(self._position[envs], subset, np.asarray(self.config.room_size))
        return gap < self.config.robot_radius

    # -- sensing ---------------------------------------------------------------------------------

    def _sense(self, envs: NDArray[np.int64]) -> NDArray[np.float64]:
        """Cast, map, fill the observation rows of ``envs``; return their f_t + v_t + p_t."""
        assert self._caster is not None and self._solids is not None
        cfg = self.config
        target = self._solids.centre[envs, 0], self._solids.size[envs, 0]
        shift = np.outer(envs * self._spacing, (1.0, 0.0, 0.0))  # rooms' places in the scene
        origin = self._position[envs] + shift
        row, ray, starts, dirs = _sensor_rays(
            origin,
            self._yaw[envs],
            self._camera,
            self._lidar,
            self._mapped,
            target[0] + shift,
            target[1],
            cfg.camera_range,
        )
        distance, tri = self._caster.cast(starts, dirs, cfg.camera_range, self.threads)
        distance = distance.astype(np.float64)
        noisy = self._noisy(envs, row, distance)
        _mark_hits(
            self._occupancy,
            envs[row],
            starts,
            dirs,
            noisy,
            shift,
            row,
            cfg.map_resolution,
        )
        face = np.where(tri >= 0, self._face_of_triangle[np.maximum(tri, 0)], -1)
        on_target = np.flatnonzero((face >= 0) & (ray < len(self._camera)))
        self._fill_depth(envs, row[on_target], ray[on_target], noisy[on_target])
        f_t = self._face_reward(
            envs, row[on_target], ray[on_target], face[on_target], distance[on_target]
        )
        self._visit(envs)
        v_t, p_t = self._fill_maps(envs)
        self._fill_state(envs)
        if self.record:
            cover = self.coverage()
            for e in envs:
                self._tracks[e].append(np.array([*self._position[e], self._yaw[e], cover[e]]))
        return f_t + v_t + p_t

    def _noisy(self, envs: NDArray[np.int64], row: NDArray, distance: NDArray) -> NDArray:
        """Ranges with Gaussian noise whose sigma grows linearly with range (Sec III-E).

        Each room draws its own noise from its own stream (rays come grouped by room).
        """
        a, b = self.config.depth_noise
        counts = np.bincount(row, minlength=len(envs))
        noise = np.concatenate(
            [self._rngs[e].standard_normal(n) for e, n in zip(envs, counts, strict=True)]
        )
        finite = np.isfinite(distance)
        clean = np.where(finite, distance, 0.0)
        noisy = np.clip(clean + noise * (a + b * clean), 0.0, self.config.camera_range)
        return np.where(finite, noisy, np.inf)

    def _fill_depth(self, envs: NDArray, row: NDArray, pixel: NDArray, noisy: NDArray) -> None:
        """D_t∘S_t: noisy z-depth on target pixels, scaled by the camera range (eq (4))."""
        width, height = self.config.image_size
        depth = np.zeros((len(envs), width * height), dtype=np.float32)
        depth[row, pixel] = noisy * self._camera_cos[pixel] / self.config.camera_range
        self._obs["depth"][envs] = depth.reshape(len(envs), 1, height, width)

    def _face_reward(
        self, envs: NDArray, row: NDArray, pixel: NDArray, face: NDArray, distance: NDArray
    ) -> NDArray[np.float64]:
        """f_t (eq (9)): scores of faces seen closer to d_ref in the focus area this step."""
        cfg = self.config
        focus = self._focus[pixel]
        key = row[focus] * TARGET_FACES + face[focus]
        size = len(envs) * TARGET_FACES
        total = np.bincount(key, weights=distance[focus], minlength=size)
        count = np.bincount(key, minlength=size)
        mean = np.divide(total, count, out=np.full(size, np.nan), where=count > 0)
        scores, best = face_scores(
            mean.reshape(len(envs), -1), self._best[envs], cfg.d_ref, cfg.alpha, cfg.beta
        )
        self._best[envs] = best
        return scores.sum(axis=1)

    def _visit(self, envs: NDArray[np.int64]) -> None:
        cell = np.floor(self._position[envs] / self.config.map_resolution).astype(np.int64)
        cell = np.clip(cell, 0, np.asarray(self._visits.shape[:0:-1]) - 1)
        np.add.at(self._visits, (envs, cell[:, 2], cell[:, 1], cell[:, 0]), 1)

    def _fill_maps(self, envs: NDArray[np.int64]) -> tuple[NDArray, NDArray]:
        """m^o and m^h (eq (3)); returns v_t (eq (10)) and p_t for the rows."""
        cfg = self.config
        n = cfg.map_cells
        occupancy = np.empty((len(envs), n**3), dtype=np.float32)
        counts = np.empty((len(envs), n**3), dtype=np.float32)
        _gather_ego(
            self._occupancy,
            self._visits,
            envs,
            self._position[envs],
            self._yaw[envs],
            self._offsets,
            cfg.map_resolution,
            occupancy,
            counts,
        )
        totals = np.empty(len(envs))
        _entropy_in_place(counts, totals)
        maps = self._obs["maps"]
        maps[envs, 0] = occupancy.reshape(len(envs), n, n, n)
        maps[envs, 1] = counts.reshape(len(envs), n, n, n) if cfg.use_svs else 0.0
        penalty = np.where(occupancy[:, self._near].any(axis=1), -1.0, 0.0)
        return semantic_search_reward(totals, cfg.gamma, cfg.delta), penalty

    def _fill_state(self, envs: NDArray[np.int64]) -> None:
        """Noisy s_t (eq (1)) in the documented layout, then a_{t-1}."""
        cfg = self.config
        half = np.asarray(cfg.room_size) / 2.0
        noise = np.stack([self._rngs[e].uniform(-1.0, 1.0, 8) for e in envs]) * cfg.state_noise
        yaw = self._yaw[envs] + noise[:, 3]
        body_v = body_from_world(self._velocity[envs], self._yaw[envs])
        state = self._obs["state"]
        state[envs, 0:3] = (self._position[envs] + noise[:, :3] - half) / half
        state[envs, 3] = np.cos(yaw / 2)
        state[envs, 4:6] = 0.0
        state[envs, 6] = np.sin(yaw / 2)
        state[envs, 7:10] = body_v + noise[:, 4:7]
        state[envs, 10:12] = 0.0
        state[envs, 12] = self._yaw_rate[envs] + noise[:, 7]
        state[envs, 13:17] = self._previous_action[envs]


class InspectionEnv(gym.Env):
    """One room as a plain ``gymnasium.Env`` (no autoreset), for tools that want a single env."""

    metadata = {"render_modes": []}  # noqa: RUF012 - gymnasium API

    def __init__(self, config: EnvConfig | None = None, seed: int = 0) -> None:
        self._vector = InspectionVectorEnv(1, config, seed=seed, autoreset=False)
        self.observation_space = self._vector.single_observation_space
        self.action_space = self._vector.single_action_space

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, NDArray[np.float32]], dict[str, Any]]:
        super().reset(seed=seed)
        obs, info = self._vector.reset(seed=seed, options=options)
        return _row(obs), {"coverage": float(info["coverage"][0])}

    def step(
        self, action: NDArray
    ) -> tuple[dict[str, NDArray[np.float32]], float, bool, bool, dict[str, Any]]:
        obs, reward, crash, timeout, info = self._vector.step(np.asarray(action)[None])
        return (
            _row(obs),
            float(reward[0]),
            bool(crash[0]),
            bool(timeout[0]),
            {"coverage": float(info["coverage"][0])},
        )


def _row(obs: dict[str, NDArray[np.float32]]) -> dict[str, NDArray[np.float32]]:
    return {key: value[0] for key, value in obs.items()}
