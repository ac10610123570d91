"""Parameters of the 004 environment, and the sizes of its state and action vectors.

Apart from :mod:`seminspect.missions.learning.env`, so that what needs only the settings (the
policy network, the training recipes, the reports) need not load the simulator.
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

#: Length of the state observation: s_t of 004 eq (1) (13 values) and a_{t-1} (4).
STATE_SIZE = 17
ACTION_SIZE = 4
#: Shapes of the semantic object (004 Sec III-E trains on primitives; Sec V meets a sphere and
#: a T-shaped pipe).
TargetShape = Literal["cylinder", "box", "sphere", "t-pipe"]
TARGET_SHAPES: tuple[TargetShape, ...] = ("cylinder", "box", "sphere", "t-pipe")
#: Room sizes of 004's training (Sec III-E): L x W x H drawn from [4, 20] x [4, 20] x [2, 8] m.
PAPER_ROOM_RANGE = ((4.0, 20.0), (4.0, 20.0), (2.0, 8.0))


class EnvConfig(BaseModel):
    """Parameters of the environment; defaults follow 004 where it gives a value."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    # -- the rooms ----------------------------------------------------------------------
    obstacles: int = Field(9, ge=0, le=60, description="obstacles per room (Table I: 0-19)")
    room_size: tuple[float, float, float] = Field(
        (10.0, 10.0, 4.0), description="every room's size unless room_size_range is set"
    )
    room_size_range: tuple[tuple[float, float], tuple[float, float], tuple[float, float]] | None = (
        Field(
            None,
            description="(low, high) per axis, drawn per room (004 training: PAPER_ROOM_RANGE)",
        )
    )
    target_shapes: tuple[TargetShape, ...] = Field(
        ("cylinder",), min_length=1, description="the object's shape, drawn per room"
    )
    obstacle_rule: Literal["surface", "target-sphere"] = Field(
        "surface",
        description="surface: obstacles anywhere that leaves the robot's width "
        "(2 robot_radius) between their surface and the object's; target-sphere (policy "
        "v1): kept 0.6 m beyond the object's bounding sphere",
    )
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
    alpha: float = Field(0.15, gt=0.0, description="eq (7) gain of the repaid face reward")
    beta: float = Field(1.0, gt=0.0, description="eq (7) distance fall-off")
    gamma: float = Field(0.005, ge=0.0, description="eq (10) gain")
    delta: float = Field(0.02, ge=0.0, description="eq (10) fall-off per visit")
    d_coll: float = Field(0.3, gt=0.0, description="collision distance (004: 0.3 m)")
    robot_radius: float = Field(0.2, gt=0.0)
    crash_penalty: float = Field(5.0, ge=0.0, description="extra penalty when a crash ends")
    use_svs: bool = Field(True, description="False: m^h is all zeros (Table II)")
    # -- what the policy sees and is paid (policy v1 trained on the legacy() values) ------
    face_reward: Literal["fraction", "repaid"] = Field(
        "fraction",
        description="fraction: f_t in [0, 1], the distance-weighted fraction of faces "
        "inspected so far, paid every step (Sec III-C); repaid (v1): alpha exp(...) at "
        "every gain toward d_ref (eq (7))",
    )
    shaping_discount: float | None = Field(
        None,
        gt=0.0,
        lt=1.0,
        description="with the fraction reward: pay f_t by potential-based shaping with "
        "Phi = f_t / (1 - this) (Ng, Harada and Russell 1999): (f_t - f_{t-1}) / (1 - this) a "
        "step, and a crash forfeits the stream. The trainer's discount, so that the best "
        "policy is the stream's, credited when a face is seen; None: f_t paid as is",
    )
    proximity_penalty: Literal["graded", "binary", "contact"] = Field(
        "graded",
        description="binary (eq (6)): -1 with an occupied m^o cell within d_coll; graded: "
        "-1 within d_coll, rising linearly to 0 at penalty_reach; contact (ours): the "
        "stronger of graded and -(1 - t_c / contact_horizon), t_c the time to contact with "
        "the occupied m^o cell the robot closes on soonest",
    )
    penalty_reach: float = Field(0.6, gt=0.0, description="graded penalty's outer edge (m)")
    contact_horizon: float = Field(
        1.0, gt=0.0, description="contact penalty: a time to contact below it costs (s)"
    )
    ego_map: Literal["three-state", "binary"] = Field(
        "three-state",
        description="three-state: m^o holds free 0, unknown 0.5, occupied 1 (rays carve free "
        "space, 004 Sec III-A); binary (v1): occupied 1, else 0, never cleared",
    )
    yaw_encoding: Literal["full-angle", "half-angle"] = Field(
        "full-angle",
        description="state slots 3 and 6: full-angle (cos yaw, sin yaw), continuous; "
        "half-angle (v1): the quaternion's (w, z), which flips sign at +-pi",
    )
    # -- the strict coverage rule (a measure only: it changes no reward) ----------------
    strict_band: float = Field(0.5, gt=0.0, description="mean range within d_ref +- this (m)")
    strict_incidence_deg: float = Field(60.0, gt=0.0, le=90.0, description="mean incidence limit")
    strict_min_pixels: int = Field(4, ge=1, description="focus-area pixels a face needs")

    @model_validator(mode="after")
    def _consistent(self) -> EnvConfig:
        if self.map_cells % 2 == 0:
            raise ValueError("map_cells must be odd so the robot sits in the centre cell")
        if min(self.room_size) <= 0 or min(self.image_size) <= 0 or min(self.lidar_beams) <= 0:
            raise ValueError("room, image and LiDAR sizes must be positive")
        if self.robot_radius > self.d_coll:
            raise ValueError("robot_radius must not exceed d_coll")
        if self.penalty_reach < self.d_coll:
            raise ValueError("penalty_reach must not be below d_coll")
        if self.room_size_range is not None and any(
            not 0.0 < low <= high for low, high in self.room_size_range
        ):
            raise ValueError("room_size_range needs 0 < low <= high on every axis")
        if len(set(self.target_shapes)) != len(self.target_shapes):
            raise ValueError(f"target_shapes repeats a shape: {self.target_shapes}")
        if self.shaping_discount is not None and self.face_reward != "fraction":
            raise ValueError("shaping_discount shapes the fraction reward only")
        return self

    @classmethod
    def legacy(cls, **changes: object) -> EnvConfig:
        """The environment policy v1 (the checkpoints without a recorded env config) was
        trained in: cylinders kept clear of obstacles, a repaid face reward, a binary penalty
        and ego map, the half-angle yaw, 45 s training episodes of 10 x 10 x 4 m rooms."""
        values: dict[str, object] = {
            "obstacle_rule": "target-sphere",
            "face_reward": "repaid",
            "proximity_penalty": "binary",
            "ego_map": "binary",
            "yaw_encoding": "half-angle",
        }
        return cls.model_validate(values | changes)

    @property
    def largest_room(self) -> tuple[float, float, float]:
        """The largest room this configuration can draw (sizes the maps and the scene)."""
        if self.room_size_range is None:
            return self.room_size
        x, y, z = (high for _, high in self.room_size_range)
        return (x, y, z)

    @property
    def steps_per_episode(self) -> int:
        return round(self.episode_seconds * self.control_hz)
