"""Parameters of the 004 environment, and the sizes of its state and action vectors.

Apart from :mod:`seminspect.missions.learning.env`, so that what needs only the settings (the
policy network, the training recipes, the reports) need not load the simulator.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, model_validator

#: Length of the state observation: s_t of 004 eq (1) (13 values) and a_{t-1} (4).
STATE_SIZE = 17
ACTION_SIZE = 4


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
