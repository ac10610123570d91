"""The learned policy beside xFLIE on the same objects (issue 28, beyond 004).

The same 004 rooms are inspected by the shipped policy (004) and by xFLIE's level-by-level
aerial inspection (000), and both are scored by the 004 camera (87 x 58 deg, 96 x 54 px) and
its strict coverage rule against the same feasible faces
(:func:`~seminspect.missions.learning.feasibility.feasible_faces`):

1. :func:`room_world` makes a seminspect :class:`World` of a room: the object is one
   instance of :data:`TARGET_CLASS`, which xFLIE is told to inspect; obstacles, walls and
   ceiling are non-target structure, the floor is the ground. The room stays closed.
2. xFLIE flies it (:func:`fly_xflie`) with the 004 robot's limits (1 m/s, 1 rad/s, 0.2 m
   radius), a level camera and its viewing distance set to 004's d_ref. Its true trajectory is
   resampled at the 004 camera's 10 Hz and replayed through the 004 environment's sensing of
   the same room (``reset(options={"rooms": ...})`` and ``observe_at``): :func:`replay_xflie`.
3. The policy flies the same rooms in its own environment (:func:`fly_policy`).

Both start at one pose: the 004 start's x, y and yaw, at the object's middle height kept
1.4 m from floor and ceiling (:func:`shared_start`). xFLIE's aerial planners keep robot
radius + 0.8 m (``AERIAL_PLANNING_MARGIN``) from everything they have mapped, floor and
ceiling included, so in a 4 m room it moves only between about 1.3 and 2.7 m; from 004's own
starts (0.6 to 3.4 m high) it often cannot take a single view step. A room whose shared start
is nearer than 0.6 m to anything (004's start clearance) is skipped and counted. This band is
also xFLIE's handicap here: 004's objects stand on the floor, 1 to 2.5 m tall, and the level
camera's focus area (the central half, +-14.5 deg) at d_ref reaches only about 0.4 m below the
camera, so faces low on the object are out of xFLIE's reach.

xFLIE's camera is the ``urban-experimental`` preset's (86 deg, 640 x 480): the nearest of
000's presets to 004's 87 deg (xFLIE's planner reads a preset, not a free field of view).
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from matplotlib.figure import Figure
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.core.rng import make_rng
from seminspect.missions.learning.agent import LearnedController
from seminspect.missions.learning.env import InspectionVectorEnv
from seminspect.missions.learning.env_config import EnvConfig
from seminspect.missions.learning.feasibility import feasible_faces
from seminspect.missions.learning.rooms import Room, clearance, sample_room
from seminspect.missions.xflie.build import build_mission
from seminspect.missions.xflie.config import (
    InspectionConfig,
    MissionConfig,
    NoiseName,
    RobotConfig,
    resolve,
)
from seminspect.missions.xflie.features import FeatureWarning
from seminspect.report.figures import new_figure
from seminspect.worlds.builder import WorldBuilder
from seminspect.worlds.world import GROUND, World

#: The object's class in the room's World: the one class xFLIE is told to inspect.
TARGET_CLASS = "pipe"
#: Class of the obstacles, walls and ceiling: structure xFLIE avoids and never inspects.
STRUCTURE_CLASS = "structure"
#: 004's start clearance (``sample_room``'s ``robot_clearance``), kept by the shared start.
START_CLEARANCE = 0.6
#: Lowest take-off height (and depth below the ceiling) from which xFLIE's aerial planners,
#: keeping robot radius + 0.8 m from 0.3 m map cells (the floor's too), took view steps in
#: trials; from 1.14 m no step was free.
XFLIE_LOWEST = 1.4
#: The nearest of 000's presets to 004's 87 deg camera (86 deg horizontal FoV).
XFLIE_PRESET = "urban-experimental"
PLANNERS = ("learned", "xflie")


def room_world(room: Room) -> World:
    """The room as a World xFLIE can fly: the target as one :data:`TARGET_CLASS` instance
    (the room's target triangles, in order), the floor as ground, the rest as structure; the
    robot starts above the floor at the room's start (its take-off height is the start's z)."""
    builder = WorldBuilder("learning-room", seed=0)
    instance = builder.new_instance(TARGET_CLASS)
    target = room.face_of_triangle >= 0
    floor = ~target & np.all(np.abs(room.vertices[room.triangles][:, :, 2]) < 1e-9, axis=1)
    builder.add_faces(room.vertices, room.triangles[target], TARGET_CLASS, "body", instance)
    builder.add_faces(room.vertices, room.triangles[floor], GROUND)
    builder.add_faces(room.vertices, room.triangles[~target & ~floor], STRUCTURE_CLASS)
    return builder.build(
        bounds=[(0.0, 0.0, 0.0), tuple(room.size)],
        start_position=(room.start[0], room.start[1], 0.0),
        start_yaw=room.start_yaw,
        metadata={"ground_z": 0.0},
    )


def shared_start(room: Room) -> Room | None:
    """The room with its start (x, y and yaw kept) at the object's middle height, within
    :data:`XFLIE_LOWEST` of floor and ceiling (the band where xFLIE's planners move); None
    when that point is nearer than :data:`START_CLEARANCE` to anything."""
    middle = float(room.target_box[:, 2].mean())
    height = min(max(middle, XFLIE_LOWEST), room.size[2] - XFLIE_LOWEST)
    start = np.array([room.start[0], room.start[1], height])
    if clearance(start[None], room.solids, room.size)[0] < START_CLEARANCE:
        return None
    return replace(room, start=start)


def study_rooms(count: int, config: EnvConfig, seed: int) -> tuple[list[Room], int]:
    """``count`` rooms of ``config`` with a shared start, drawn from ``seed`` in order, and
    how many drawn rooms were skipped (no clear shared start, :func:`shared_start`)."""
    rooms: list[Room] = []
    skipped = 0
    while len(rooms) < count:
        if skipped > 10 * count:  # a room kind whose starts never clear: say so, not loop
            raise InvalidInputError(f"{skipped} rooms of {count} wanted had no clear start")
        rng = make_rng(seed, "studies", "versus-xflie", f"room-{len(rooms) + skipped}")
        room = shared_start(sample_room(rng, config.obstacles, config))
        if room is None:
            skipped += 1
        else:
            rooms.append(room)
    return rooms, skipped


def xflie_config(
    room: Room, config: EnvConfig, seconds: float, seed: int, noise: NoiseName
) -> MissionConfig:
    """xFLIE's aerial mission in ``room`` with the 004 robot's limits, a level camera and the
    viewing distance at 004's d_ref (the middle of the strict rule's range band)."""
    return MissionConfig(
        world="learning-room",
        seed=seed,
        preset=XFLIE_PRESET,
        mode="aerial",
        noise=noise,
        time_budget_s=seconds,
        target_classes=(TARGET_CLASS,),
        robot=RobotConfig(
            radius=config.robot_radius,
            speed=config.max_speed,
            yaw_rate=config.max_yaw_rate,
            flight_height=float(room.start[2]),
            camera_pitch_deg=0.0,
        ),
        inspection=InspectionConfig(d_view=config.d_ref, save_images=False),
    )


@dataclass(frozen=True)
class XFlieFlight:
    """One xFLIE mission: its true ``(T, 5)`` trajectory rows (t, x, y, z, unwrapped yaw) and
    why it stopped."""

    trajectory: NDArray[np.float64]
    stop_reason: str


def fly_xflie(
    room: Room, config: EnvConfig, seconds: float, seed: int, noise: NoiseName = "realistic"
) -> XFlieFlight:
    """xFLIE's aerial mission in ``room`` for at most ``seconds`` of simulated time."""
    world = room_world(room)
    mission_config = resolve(xflie_config(room, config, seconds, seed, noise), world)
    with warnings.catch_warnings():  # the object has no parts: no features, as intended
        warnings.simplefilter("ignore", FeatureWarning)
        mission, _ = build_mission(mission_config, None, world=world)
    reason = mission.execute()
    return XFlieFlight(mission.platform.trajectory_rows()[:, :5], reason)


def resample(trajectory: NDArray[np.float64], times: NDArray[np.float64]) -> NDArray[np.float64]:
    """``(len(times), 4)`` poses (x, y, z, yaw) at ``times``, linear between the rows as the
    robot moves (its yaw is unwrapped, so it turns the short way it did); held after the end."""
    t = trajectory[:, 0]
    return np.stack([np.interp(times, t, trajectory[:, k]) for k in range(1, 5)], axis=1)


@dataclass(frozen=True)
class Flown:
    """What one planner did in every room: strictly seen faces ``(N, seconds + 1, 60)`` at
    each whole second (held after its run ended), crashes and when each run ended (s)."""

    seen: NDArray[np.bool_]
    crashed: NDArray[np.bool_]
    ended_s: NDArray[np.float64]


def _per_second(ticks: NDArray[np.bool_], ended: NDArray[np.float64], hz: float) -> NDArray:
    """``(N, S + 1, 60)`` from per-tick ``(T + 1, N, 60)`` snapshots: at second s the snapshot
    of tick min(s hz, the room's last tick before its end)."""
    count = ticks.shape[0]
    last = np.minimum(np.floor(ended * hz + 1e-9), count - 1).astype(np.int64)
    seconds = np.arange(0, count, round(hz))
    index = np.minimum(seconds[None, :], last[:, None])  # (N, S + 1)
    return ticks[index, np.arange(ticks.shape[1])[:, None]]


def replay_xflie(
    rooms: Sequence[Room], flights: Sequence[XFlieFlight], config: EnvConfig, seconds: int
) -> Flown:
    """xFLIE's trajectories through the 004 camera at ``control_hz`` (``observe_at``). A pose
    nearer than ``robot_radius`` to anything (004's crash) ends the room's run there, as it
    ends a 004 episode; so does the trajectory's end."""
    hz = config.control_hz
    times = np.arange(round(seconds * hz) + 1) / hz
    poses = np.stack([resample(f.trajectory, times) for f in flights])  # (N, T + 1, 4)
    gap = np.stack(
        [clearance(p[:, :3], r.solids, r.size) for p, r in zip(poses, rooms, strict=True)]
    )
    hit = gap < config.robot_radius
    crashed = np.asarray(hit.any(axis=1))
    crash_s = np.where(crashed, times[hit.argmax(axis=1)], np.inf)
    ended = np.minimum([f.trajectory[-1, 0] for f in flights], crash_s)
    env = InspectionVectorEnv(len(rooms), config, seed=0, autoreset=False)
    env.reset(options={"rooms": list(rooms)})  # senses at the start: tick 0
    ticks = [env.strict_seen()]
    for tick in range(1, len(times)):
        env.observe_at(poses[:, tick, :3], poses[:, tick, 3])
        ticks.append(env.strict_seen())
    return Flown(_per_second(np.array(ticks), ended, hz), crashed, ended)


def fly_policy(
    rooms: Sequence[Room], controller: LearnedController, config: EnvConfig, seconds: int
) -> Flown:
    """The learned policy in ``rooms`` for ``seconds`` (or until it crashes), in ``config``."""
    hz = config.control_hz
    env = InspectionVectorEnv(len(rooms), config, seed=0, autoreset=False)
    obs, _ = env.reset(options={"rooms": list(rooms)})
    controller.reset(env)
    ticks = [env.strict_seen()]
    ended = np.full(len(rooms), float(seconds))
    crashed = np.zeros(len(rooms), dtype=bool)
    for tick in range(1, round(seconds * hz) + 1):
        obs, _, crash, _, _ = env.step(controller.act(env, obs))
        ended[crash] = tick / hz
        crashed |= crash
        ticks.append(env.strict_seen())  # a finished room is frozen: its faces stay
    return Flown(_per_second(np.array(ticks), ended, hz), crashed, ended)


def strict_curves(flown: Flown, feasible: NDArray[np.bool_]) -> NDArray[np.float64]:
    """``(N, S + 1)`` strict coverage %: 100 |seen| / |feasible or seen at the end| (a face
    seen strictly was feasible); a room with no such face scores 100."""
    scored = (feasible | flown.seen[:, -1]).sum(axis=1)
    counts = flown.seen.sum(axis=2)
    out = np.full(counts.shape, 100.0)
    return np.divide(100.0 * counts, scored[:, None], out=out, where=scored[:, None] > 0)


@dataclass(frozen=True)
class VersusResult:
    """Strict coverage against time of both planners in the same rooms.

    ``curves[planner]`` is ``(rooms, seconds + 1)`` strict coverage % at each whole second;
    ``crashed`` and ``ended_s`` are per room; ``shapes`` the rooms' object shapes;
    ``stop_reasons`` xFLIE's; ``skipped`` the rooms drawn without a clear shared start;
    ``wall_s`` the wall time of each planner's part.
    """

    curves: dict[str, NDArray[np.float64]]
    crashed: dict[str, NDArray[np.bool_]]
    ended_s: dict[str, NDArray[np.float64]]
    shapes: list[str]
    feasible: list[int]
    stop_reasons: list[str]
    skipped: int
    wall_s: dict[str, float]

    @property
    def times(self) -> NDArray[np.float64]:
        return np.arange(next(iter(self.curves.values())).shape[1], dtype=np.float64)


def run_versus(
    controller: LearnedController,
    config: EnvConfig,
    rooms: int,
    *,
    seed: int = 0,
    seconds: int = 180,
    noise: NoiseName = "realistic",
) -> VersusResult:
    """Both planners in ``rooms`` rooms of ``config`` (its ``episode_seconds`` is set to
    ``seconds``, the horizon of both), scored by the same camera and strict rule."""
    cfg = config.model_copy(update={"episode_seconds": float(seconds)})
    drawn, skipped = study_rooms(rooms, cfg, seed)
    feasible = np.array([feasible_faces(room, cfg, seed) for room in drawn])
    started = time.perf_counter()
    flights = [fly_xflie(room, cfg, seconds, seed, noise) for room in drawn]
    replayed = replay_xflie(drawn, flights, cfg, seconds)
    middle = time.perf_counter()
    learned = fly_policy(drawn, controller, cfg, seconds)
    wall = {"xflie": middle - started, "learned": time.perf_counter() - middle}
    flown = {"learned": learned, "xflie": replayed}
    return VersusResult(
        curves={name: strict_curves(f, feasible) for name, f in flown.items()},
        crashed={name: f.crashed for name, f in flown.items()},
        ended_s={name: f.ended_s for name, f in flown.items()},
        shapes=[room.shape for room in drawn],
        feasible=feasible.sum(axis=1).tolist(),
        stop_reasons=[f.stop_reason for f in flights],
        skipped=skipped,
        wall_s=wall,
    )


def time_to(curves: NDArray[np.float64], level: float) -> NDArray[np.float64]:
    """Per room, the first second its strict coverage reaches ``level`` % (inf: never)."""
    reached = curves >= level
    return np.where(reached.any(axis=1), reached.argmax(axis=1), np.inf).astype(np.float64)


def _median_time(times: NDArray[np.float64]) -> str:
    """Median over the rooms that got there, and how many did."""
    done = times[np.isfinite(times)]
    middle = f"{np.median(done):.0f} s" if len(done) else "-"
    return f"{middle} ({len(done)}/{len(times)})"


def _spread(values: NDArray[np.float64]) -> str:
    low, high = np.percentile(values, (5, 95))
    return f"{values.mean():.1f} [{low:.1f}-{high:.1f}]"


def versus_markdown(result: VersusResult, at_s: int = 90) -> str:
    """A row per planner (and per shape when there are several): strict coverage at ``at_s``
    and at the end (mean [5th-95th percentile]), median time to 50 % and 80 % of the
    feasible (rooms that got there), crashes."""
    groups = [("all", np.ones(len(result.shapes), dtype=bool))]
    if len(set(result.shapes)) > 1:
        groups += [(s, np.array(result.shapes) == s) for s in sorted(set(result.shapes))]
    at = min(at_s, len(result.times) - 1)
    end = len(result.times) - 1
    lines = [
        f"| planner | shape | rooms | strict % at {at} s | strict % at {end} s "
        "| time to 50 % | time to 80 % | crashes |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name in PLANNERS:
        for shape, mask in groups:
            curves = result.curves[name][mask]
            lines.append(
                f"| {name} | {shape} | {int(mask.sum())} | {_spread(curves[:, at])} "
                f"| {_spread(curves[:, -1])} | {_median_time(time_to(curves, 50.0))} "
                f"| {_median_time(time_to(curves, 80.0))} "
                f"| {int(result.crashed[name][mask].sum())} |"
            )
    return "\n".join(lines)


def versus_figure(result: VersusResult) -> Figure:
    """Strict coverage % of the feasible against time, both planners: mean and 5th-95th
    percentile over the rooms; dotted: the 50 % and 80 % marks."""
    figure = new_figure(6.4, 3.8)
    ax = figure.add_subplot()
    labels = {"learned": "learned policy (004)", "xflie": "xFLIE, aerial (000)"}
    for name in PLANNERS:
        curves = result.curves[name]
        (line,) = ax.plot(result.times, curves.mean(axis=0), label=labels[name])
        low, high = np.percentile(curves, (5, 95), axis=0)
        ax.fill_between(result.times, low, high, color=line.get_color(), alpha=0.15)
    for level in (50.0, 80.0):
        ax.axhline(level, color="0.5", linestyle=":", linewidth=0.8)
    ax.set_ylim(0, 101)
    ax.set_xlim(0, result.times[-1])
    ax.set_xlabel("time [s]")
    ax.set_ylabel("strict coverage [% of feasible]")
    ax.set_title(f"{len(result.shapes)} rooms, same camera and strict rule", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    figure.tight_layout()
    return figure
