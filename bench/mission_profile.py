"""Where a mission's wall time goes, stage by stage, against its ray-casting floor.

Runs one fixed xFLIE mission (default: city small, seed 0, as configured by ``make_config``)
and splits its wall time into stages:

* ray casting: ``RayCaster.cast`` (Embree), for camera frames, LiDAR scans and any other query;
* rendering: what ``render`` does around the rays (shading, labels, intensity texture);
* noise: the image noise of a frame (where the mission draws it ahead on a worker thread,
  ``sensors.noise.NormalStream``, the compiled pass and any wait for the draw);
* map integration: what the mission's thread spends on it: ``VoxelMap.integrate_rays``
  (preparing the rays and, on one thread, walking them) and ``VoxelMap.settle`` (waiting for
  the walks handed to the map's worker thread, with a second core);
* the mission's own categories for the rest (perception, planning, graph, driving, and
  sensing left after the stages above), and I/O and setup as what no timer covers.

The stages are timed by wrapping those functions for the run only, and charged to the mission's
own ``Timers`` so that nested time counts once. The figure to drive down is the ratio of the
total wall time to the ray-casting time (issue 16: <= 2.0). Ray casting is wall time: where a
mission casts on two threads (``core.threads.sensor_threads``, ``SEMINSPECT_THREADS=1`` for
one) it counts once, however many cores it kept busy.

``--float32-image-noise`` runs the mission with ``NoiseModel.image_noise_float32`` on, which
draws the image noise faster but changes the mission's numbers; the outcome line (detected,
inspected, localisation RMSE) shows by how much.

Run: ``PYTHONPATH=src .venv/bin/python bench/mission_profile.py [--scenario small] [--seed 0]``
"""

from __future__ import annotations

import argparse
import tempfile
import time
from collections import defaultdict
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager, suppress
from functools import wraps
from typing import Any

from seminspect.mapping import voxel
from seminspect.missions.xflie import metrics, run
from seminspect.missions.xflie.config import make_config
from seminspect.missions.xflie.run import run_mission
from seminspect.platform import simulated as platform
from seminspect.sensors import NoiseModel, camera
from seminspect.worlds import raycast

#: (module, attribute, stage): the functions timed as their own stage.
STAGES = (
    (raycast.RayCaster, "cast", "ray casting"),
    (camera, "shade_hits", "rendering"),
    (platform, "render", "rendering"),
    (camera, "_add_image_noise", "noise"),
    (voxel.VoxelMap, "integrate_rays", "map integration"),
    (voxel.VoxelMap, "settle", "map integration"),
)


class _Registry:
    """The mission's ``Timers`` (captured at construction), or a private one before it."""

    def __init__(self) -> None:
        self.timers: metrics.Timers = metrics.Timers()
        self.every = [self.timers]

    def seconds(self) -> dict[str, float]:
        """Seconds per stage and category, over the private timers and the mission's."""
        total: dict[str, float] = defaultdict(float)
        for timers in self.every:
            for name, value in timers.seconds.items():
                total[name] += value
        return dict(total)

    def timed(self, stage: str, function: Callable[..., Any]) -> Callable[..., Any]:
        @wraps(function)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            with self.timers(stage):
                return function(*args, **kwargs)

        return wrapper


def outcome(figures: metrics.MissionMetrics) -> str:
    """The mission's results, to compare settings that may change them."""
    rmse = figures.table6.localisation_rmse_m
    return (
        f"targets detected {figures.table3.detected_pct:.0f} %, inspected "
        f"{figures.table3.inspected_pct:.0f} % of detected; localisation RMSE "
        f"{'-' if rmse is None else f'{rmse:.3f} m'}; {figures.mission.distance_m:.0f} m driven"
    )


@contextmanager
def staged(registry: _Registry) -> Iterator[None]:
    """Wrap the stage functions and capture the mission's timers, for the block only."""
    original_init = metrics.Timers.__init__
    saved = [(owner, name, getattr(owner, name)) for owner, name, _ in STAGES]

    def capturing_init(timers: metrics.Timers) -> None:
        original_init(timers)
        registry.timers = timers
        registry.every.append(timers)

    metrics.Timers.__init__ = capturing_init  # type: ignore[method-assign]
    for owner, name, stage in STAGES:
        setattr(owner, name, registry.timed(stage, getattr(owner, name)))
    try:
        yield
    finally:
        metrics.Timers.__init__ = original_init  # type: ignore[method-assign]
        for owner, name, function in saved:
            setattr(owner, name, function)


@contextmanager
def float32_image_noise() -> Iterator[None]:
    """Run the mission with ``NoiseModel.image_noise_float32`` on (other numbers than published)."""
    original = run.mission_noise

    def single_precision(*args: Any) -> NoiseModel:
        return original(*args).model_copy(update={"image_noise_float32": True})

    run.mission_noise = single_precision
    try:
        yield
    finally:
        run.mission_noise = original


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--world", default="city")
    parser.add_argument("--scenario", default="small")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--float32-image-noise",
        action="store_true",
        help="draw the image noise in single precision (changes the mission's numbers)",
    )
    parser.add_argument(
        "--carving-spacing", type=float, help="thinned free-space carving (cells; default exact)"
    )
    args = parser.parse_args()

    settings = {"world": args.world, "scenario": args.scenario, "seed": args.seed}
    if args.carving_spacing is not None:  # left out otherwise: the script also runs older code
        settings["map_carving_spacing"] = args.carving_spacing
    config = make_config(settings)
    registry = _Registry()
    with ExitStack() as stack:
        out = stack.enter_context(tempfile.TemporaryDirectory())
        stack.enter_context(staged(registry))
        if args.float32_image_noise:
            stack.enter_context(float32_image_noise())
        start = time.perf_counter()
        result = run_mission(config, f"{out}/run")
        wall = time.perf_counter() - start
    figures = result.metrics
    assert figures is not None, f"the mission stopped before its figures: {result.reason}"
    mission = figures.mission
    seconds = registry.seconds()
    with suppress(KeyError):
        seconds["sensing (other)"] = seconds.pop("sensing")
    seconds["I/O, setup (untimed)"] = wall - sum(seconds.values())
    casting = seconds.get("ray casting", 0.0)
    print(f"mission {args.world} {args.scenario} seed {args.seed}: {result.state}")
    print(
        f"simulated {mission.sim_time_s:.0f} s in {wall:.1f} s wall: "
        f"{mission.sim_time_s / wall:.1f}x real time; {mission.frames} frames, "
        f"{mission.lidar_scans} scans"
    )
    print(outcome(figures))
    print(f"{'stage':<22} {'seconds':>8} {'share':>7}")
    for stage, value in sorted(seconds.items(), key=lambda item: -item[1]):
        print(f"{stage:<22} {value:8.2f} {100 * value / wall:6.1f}%")
    print(f"total / ray casting: {wall / casting:.2f}  (target <= 2.0)")


if __name__ == "__main__":
    main()
