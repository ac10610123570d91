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
  (sigma growing linearly with range, Sec III-E) update the robot's own 0.1 m map (range data
  only, Sec III-A): three-state (``ego_map``) carves free space along the beams and mapping
  pixels and marks every return occupied; binary (policy v1) only marks returns.
- Observation eq (4): state s_t (eq (1)) with uniform noise, the previous action, the masked
  depth D_t∘S_t, the ego-centric occupancy map m^o (free 0, unknown 0.5, occupied 1; binary:
  occupied and outside the map 1, else 0) and the spatial visit score map m^h (eq (3)), both
  21^3 at 0.1 m in the yaw-aligned body frame.
- Reward eq (6): face-mesh reward f_t (eqs (7)-(9), focus-area faces only: the distance-
  weighted fraction inspected, as is or shaped, or v1's repaid scores), semantic-search reward
  v_t (eq (10)) and the penalty p_t (:mod:`.rewards`: binary, graded or contact). Contact (true
  clearance below the robot radius) is a crash: it ends the episode and costs ``crash_penalty``
  (and a shaped reward's potential); reaching the episode length is a timeout (Sec IV-A).
  Coverage: lenient and strict (a measure only).

The parts have modules of their own: :mod:`.env_config` (the settings), :mod:`.sensors`,
:mod:`.maps`, :mod:`.rewards`, :mod:`.face_views` and :mod:`.dynamics` (with the state
vector's layout); this one steps them together.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.core.rng import make_rng
from seminspect.geometry.transforms import body_from_world, world_from_body
from seminspect.missions.learning.dynamics import first_order_step, state_rows
from seminspect.missions.learning.env_config import ACTION_SIZE, STATE_SIZE, EnvConfig
from seminspect.missions.learning.face_views import (
    FaceRecord,
    face_views,
    incidence_degrees,
    triangle_normals,
)
from seminspect.missions.learning.maps import (
    BINARY_VALUES,
    THREE_STATE_VALUES,
    ego_maps,
    ego_offsets,
    spatial_visit_scores,
    update_maps,
)
from seminspect.missions.learning.rewards import (
    collision_penalty,
    contact_penalty,
    graded_penalty,
    semantic_search_reward,
)
from seminspect.missions.learning.rooms import (
    TARGET_FACES,
    Room,
    checked_rooms,
    clearance,
    sample_room,
    side_by_side,
    stack_solids,
)
from seminspect.missions.learning.sensors import (
    camera_rays,
    focus_mask,
    lidar_rays,
    mapping_pixels,
    noisy_ranges,
    sensor_rays,
)
from seminspect.worlds.raycast import RayCaster

#: Gap between neighbouring rooms in the shared ray-casting scene (metres).
ROOM_GAP = 2.0


class InspectionVectorEnv(gym.vector.VectorEnv):
    """``num_envs`` rooms stepped together (SAME_STEP autoreset unless ``autoreset=False``).

    Without autoreset a finished room is frozen (zero reward, unchanged observation) until the
    next :meth:`reset`, which suits evaluation: every room runs exactly one episode. ``threads``:
    ray casting's and the map kernels' (blocks of rooms); the results never depend on it.
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
        cfg = self.config
        self._camera, self._camera_cos = camera_rays(cfg.image_size, cfg.fov_deg)
        self._lidar = lidar_rays(cfg.lidar_beams)
        self._focus = focus_mask(cfg.image_size)
        self._mapped = mapping_pixels(cfg.image_size)
        # The rays that carve free space: the mapping pixels and every beam, wherever the
        # target is (its pixels too would double the walks for 0.003 % of the ego cells)
        self._carving = np.concatenate([self._mapped, np.ones(len(self._lidar), dtype=bool)])
        self._offsets = ego_offsets(cfg.map_cells, cfg.map_resolution)
        radius = np.linalg.norm(self._offsets, axis=1)  # the m^o cells p_t reads, how far
        reach = cfg.d_coll if cfg.proximity_penalty == "binary" else cfg.penalty_reach
        self._near = np.flatnonzero(radius <= reach)
        self._near_radius = radius[self._near]
        # the contact penalty looks as far as the map reaches on every side
        self._ahead = np.flatnonzero(radius <= cfg.map_cells // 2 * cfg.map_resolution)
        self._cell_values = BINARY_VALUES if cfg.ego_map == "binary" else THREE_STATE_VALUES
        self._spacing = self.config.largest_room[0] + ROOM_GAP  # rooms drawn smaller fit too

    def _allocate(self) -> None:
        count, cfg = self.num_envs, self.config
        cells = np.ceil(np.asarray(cfg.largest_room) / cfg.map_resolution).astype(int)
        # z, y, x order: the ego cells are walked x-fastest, so lookups stay close in memory.
        self._occupancy = np.zeros((count, *cells[::-1]), dtype=np.uint8)
        self._visits = np.zeros((count, *cells[::-1]), dtype=np.uint16)
        self._position = np.zeros((count, 3))
        self._room_size = np.tile(np.asarray(cfg.room_size, dtype=np.float64), (count, 1))
        self._velocity = np.zeros((count, 3))
        self._yaw = np.zeros(count)
        self._yaw_rate = np.zeros(count)
        self._previous_action = np.zeros((count, ACTION_SIZE), dtype=np.float32)
        self._faces = FaceRecord(count, cfg)
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
        return (self._faces.best <= self.config.inspect_range).mean(axis=1)

    def strict_seen(self) -> NDArray[np.bool_]:
        """``(num_envs, faces)``: faces the strict rule passed once (a measure: no reward)."""
        return self._faces.strict.copy()

    def distance_scores(self) -> NDArray[np.float64]:
        """``(num_envs, faces)``: best distance score s(d) of any focus-area view (0: unseen)."""
        return self._faces.distance_scores()

    def positions(self) -> NDArray[np.float64]:
        """True ``(num_envs, 3)`` robot positions in room coordinates (for baselines, pictures)."""
        return self._position.copy()

    def yaws(self) -> NDArray[np.float64]:
        """True robot headings (rad)."""
        return self._yaw.copy()

    def face_distances(self, env: int) -> NDArray[np.float64]:
        """Best viewing distance d_f of each target face of one room (inf: never seen)."""
        return self._faces.best[env].copy()

    def track(self, env: int) -> NDArray[np.float64]:
        """Recorded ``(T, 5)`` rows (x, y, z, yaw, coverage) of one room's episode."""
        if not self.record:
            raise InvalidInputError("tracks are kept only with record=True")
        return np.array(self._tracks[env]).reshape(-1, 5)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, NDArray[np.float32]], dict[str, Any]]:
        """``options``: ``obstacles`` (counts, see :meth:`set_obstacles`) and ``rooms`` (one
        :class:`Room` per env for this episode instead of drawn ones; autoreset draws again)."""
        if seed is not None:
            self._seed = seed
            self._rngs = [make_rng(seed, "learning", f"env-{i}") for i in range(self.num_envs)]
        if options and "obstacles" in options:
            self.set_obstacles(options["obstacles"])
        if options and "rooms" in options:
            self._rooms = checked_rooms(options["rooms"], self.num_envs, self.config.largest_room)
        else:
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
        crashed = np.flatnonzero(crash)
        reward[crashed] -= self.config.crash_penalty + self._faces.crash_forfeit(crashed)
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

    def observe_at(self, positions: ArrayLike, yaws: ArrayLike) -> dict[str, NDArray[np.float32]]:
        """Put each robot at a pose, at rest (velocity, yaw rate and a_{t-1} zero), and sense
        as a step does: maps, face distances, strict flags. Replays another planner's
        ``(num_envs, 3)`` positions and yaws through this camera; no step is counted."""
        if self._caster is None:
            raise InvalidInputError("call reset() before observe_at()")
        position = np.asarray(positions, dtype=np.float64)
        yaw = np.asarray(yaws, dtype=np.float64)
        if position.shape != (self.num_envs, 3) or yaw.shape != (self.num_envs,):
            raise InvalidInputError(
                f"observe_at needs ({self.num_envs}, 3) positions and ({self.num_envs},) yaws, "
                f"got {position.shape} and {yaw.shape}"
            )
        if not (np.all(np.isfinite(position)) and np.all(np.isfinite(yaw))):
            raise InvalidInputError("poses must be finite")
        self._position[:] = position
        self._yaw[:] = (yaw + math.pi) % (2.0 * math.pi) - math.pi  # as _move wraps
        self._velocity[:] = 0.0
        self._yaw_rate[:] = 0.0
        self._previous_action[:] = 0.0
        self._sense(np.arange(self.num_envs))
        return self._copy_obs()

    # -- episode bookkeeping -------------------------------------------------------------------

    def _sample_room(self, env: int) -> Room:
        return sample_room(self._rngs[env], int(self._obstacles[env]), self.config)

    def _begin(self, envs: NDArray[np.int64]) -> None:
        for env in envs:
            room = self._rooms[env]
            self._position[env] = room.start
            self._room_size[env] = room.size
            self._yaw[env] = room.start_yaw
            self._tracks[env] = []
        self._velocity[envs] = 0.0
        self._yaw_rate[envs] = 0.0
        self._previous_action[envs] = 0.0
        self._occupancy[envs] = 0
        self._visits[envs] = 0
        self._faces.clear(envs)
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
        vertices, triangles, self._face_of_triangle = side_by_side(self._rooms, self._spacing)
        self._caster = RayCaster(vertices, triangles)
        target = self._face_of_triangle >= 0  # normals for the strict rule's incidence
        self._normals = np.zeros((len(triangles), 3))
        self._normals[target] = triangle_normals(vertices, triangles[target])

    def _copy_obs(self) -> dict[str, NDArray[np.float32]]:
        return {key: value.copy() for key, value in self._obs.items()}

    # -- dynamics --------------------------------------------------------------------------------

    def _move(self, envs: NDArray[np.int64], action: NDArray[np.float32]) -> None:
        """Exact first-order velocity response over one step, with a disturbance (eq (5))."""
        cfg = self.config
        dt, tau = 1.0 / cfg.control_hz, cfg.velocity_time_constant
        a = action[envs].astype(np.float64)
        command = world_from_body(a[:, :3] * cfg.max_speed, self._yaw[envs])
        push = np.stack([self._rngs[e].normal(0.0, cfg.disturbance_std, 3) for e in envs])
        command += push * tau
        moved, self._velocity[envs] = first_order_step(self._velocity[envs], command, dt, tau)
        self._position[envs] += moved
        yaw_command = a[:, 3] * cfg.max_yaw_rate
        turned, self._yaw_rate[envs] = first_order_step(self._yaw_rate[envs], yaw_command, dt, tau)
        self._yaw[envs] += turned
        # [-pi, pi) by floor modulo; wrap_angle's remainder rounds otherwise
        self._yaw[envs] = (self._yaw[envs] + math.pi) % (2.0 * math.pi) - math.pi
        self._previous_action[envs] = action[envs]

    def _crashed(self, envs: NDArray[np.int64]) -> NDArray[np.bool_]:
        solids = self._solids
        assert solids is not None
        gap = clearance(self._position[envs], solids.rows(envs), self._room_size[envs])
        return gap < self.config.robot_radius

    # -- sensing ---------------------------------------------------------------------------------

    def _sense(self, envs: NDArray[np.int64]) -> NDArray[np.float64]:
        """Cast, map, fill the observation rows of ``envs``; return their f_t + v_t + p_t."""
        assert self._caster is not None and self._solids is not None
        cfg = self.config
        shift = np.outer(envs * self._spacing, (1.0, 0.0, 0.0))  # rooms' places in the scene
        target_box = np.stack([self._rooms[e].target_box for e in envs]) + shift[:, None]
        origin = self._position[envs] + shift
        row, ray, starts, dirs = sensor_rays(
            origin, self._yaw[envs], self._camera, self._lidar, self._mapped, target_box,
            cfg.camera_range, self.threads,
        )  # fmt: skip
        distance, tri = self._caster.cast(starts, dirs, cfg.camera_range, self.threads)
        distance = distance.astype(np.float64)
        noisy = self._noisy(envs, row, distance)
        carve = self._carving[ray] if cfg.ego_map == "three-state" else None
        update_maps(
            self._occupancy, envs[row], starts, dirs, noisy, shift, row, cfg.map_resolution,
            carve, cfg.camera_range, self.threads,
        )  # fmt: skip
        face = np.where(tri >= 0, self._face_of_triangle[np.maximum(tri, 0)], -1)
        on_target = np.flatnonzero((face >= 0) & (ray < len(self._camera)))
        self._fill_depth(envs, row[on_target], ray[on_target], noisy[on_target])
        seen = on_target[self._focus[ray[on_target]]]  # only the focus area counts (Sec III-C)
        views = face_views(
            row[seen] * TARGET_FACES + face[seen],
            distance[seen],
            incidence_degrees(self._normals[tri[seen]], dirs[seen]),
            len(envs) * TARGET_FACES,
        )
        f_t = self._faces.update(envs, views)
        self._visit(envs)
        v_t, p_t = self._fill_maps(envs)
        self._fill_state(envs)
        if self.record:
            cover = self.coverage()
            for e in envs:
                self._tracks[e].append(np.array([*self._position[e], self._yaw[e], cover[e]]))
        return f_t + v_t + p_t

    def _noisy(self, envs: NDArray[np.int64], row: NDArray, distance: NDArray) -> NDArray:
        """:func:`noisy_ranges`, each room drawing its noise from its own stream (the rays come
        grouped by room)."""
        bounds = np.searchsorted(row, np.arange(len(envs) + 1))
        noise = np.empty(len(row))  # filled in place: the values of one draw per room, no concat
        for e, start, end in zip(envs, bounds[:-1], bounds[1:], strict=True):
            self._rngs[e].standard_normal(out=noise[start:end])
        return noisy_ranges(distance, noise, self.config.depth_noise, self.config.camera_range)

    def _fill_depth(self, envs: NDArray, row: NDArray, pixel: NDArray, noisy: NDArray) -> None:
        """D_t∘S_t: noisy z-depth on target pixels, scaled by the camera range (eq (4))."""
        width, height = self.config.image_size
        depth = np.zeros((len(envs), width * height), dtype=np.float32)
        depth[row, pixel] = noisy * self._camera_cos[pixel] / self.config.camera_range
        self._obs["depth"][envs] = depth.reshape(len(envs), 1, height, width)

    def _visit(self, envs: NDArray[np.int64]) -> None:
        cell = np.floor(self._position[envs] / self.config.map_resolution).astype(np.int64)
        cell = np.clip(cell, 0, np.asarray(self._visits.shape[:0:-1]) - 1)
        np.add.at(self._visits, (envs, cell[:, 2], cell[:, 1], cell[:, 0]), 1)

    def _fill_maps(self, envs: NDArray[np.int64]) -> tuple[NDArray, NDArray]:
        """m^o and m^h (eq (3)); returns v_t (eq (10)) and p_t for the rows."""
        cfg = self.config
        n = cfg.map_cells
        occupancy, counts = ego_maps(
            self._occupancy, self._visits, envs, self._position[envs], self._yaw[envs],
            self._offsets, cfg.map_resolution, self._cell_values, self.threads,
        )  # fmt: skip
        scores, totals = spatial_visit_scores(counts)
        maps = self._obs["maps"]
        maps[envs, 0] = occupancy.reshape(len(envs), n, n, n)
        maps[envs, 1] = scores.reshape(len(envs), n, n, n) if cfg.use_svs else 0.0
        near = occupancy[:, self._near]
        if cfg.proximity_penalty == "binary":
            penalty = collision_penalty(near)
        else:
            penalty = graded_penalty(near, self._near_radius, cfg.d_coll, cfg.penalty_reach)
        if cfg.proximity_penalty == "contact":  # the map's cells lie in the yaw-aligned frame
            velocity = body_from_world(self._velocity[envs], self._yaw[envs])
            closing = contact_penalty(
                occupancy[:, self._ahead], self._offsets[self._ahead], velocity,
                cfg.robot_radius, cfg.contact_horizon,
            )  # fmt: skip
            penalty = np.minimum(penalty, closing)
        return semantic_search_reward(totals, cfg.gamma, cfg.delta), penalty

    def _fill_state(self, envs: NDArray[np.int64]) -> None:
        """Noisy s_t (eq (1), :func:`.dynamics.state_rows`), then a_{t-1}."""
        noise = np.stack([self._rngs[e].uniform(-1.0, 1.0, 8) for e in envs])
        state = self._obs["state"]
        state[envs, :13] = state_rows(
            self._position[envs], self._room_size[envs], self._yaw[envs], self._velocity[envs],
            self._yaw_rate[envs], noise * self.config.state_noise, self.config.yaw_encoding,
        )  # fmt: skip
        state[envs, 13:17] = self._previous_action[envs]

    # -- pickling (a training run's saved state) ------------------------------------------------

    def __getstate__(self) -> dict[str, Any]:
        """Every attribute but the ray caster, rebuilt from the rooms on load: its Embree scene
        would pickle as a bare handle into this process's memory."""
        return self.__dict__ | {"_caster": None}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state)
        if self._rooms:
            self._rebuild_scene()
