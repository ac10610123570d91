"""Casting a camera frame on two threads: contiguous halves against blocks dealt out.

A frame's top rows (sky, far walls) cast in about half the time of its bottom rows, so when
each of two threads takes one contiguous half, one waits for the other;
``core.threads.run_dealt`` cuts the frame into eight blocks per thread, which the threads take
one at a time as each comes free. For street poses of a city (only the world's own Embree scene
in the process, as in a mission) this prints, per pose, the best of ``--repeats`` times of: the
top and the bottom half alone, the whole frame on one thread, in two halves on two threads, and
dealt out on two threads.

Run: ``PYTHONPATH=src:bench .venv/bin/python bench/casting_threads.py [--poses 4]``
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np
from scipy.spatial.transform import Rotation

from seminspect.core.threads import thread_pool
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.sensors import CameraModel
from seminspect.worlds import generate_world
from sensors import street_poses


def best_ms(call: Callable[[], object], repeats: int) -> float:
    """The fastest of ``repeats`` back-to-back calls (an idle core of a virtual machine can take
    milliseconds to wake; a mission casting without pause does not wait for it)."""
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - start)
    return 1e3 * best


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scenario", default="medium")
    parser.add_argument("--poses", type=int, default=4)
    parser.add_argument("--repeats", type=int, default=6)
    args = parser.parse_args()

    world = generate_world("city", args.scenario, seed=0)
    camera, caster = CameraModel(), world.raycaster
    body, _ = camera.rays
    half = len(body) // 2
    print(f"city {args.scenario}, 640 x 480 frames, best of {args.repeats} (ms):")
    print("  top half  bottom half   one thread   two: halves   two: dealt   dealt / one")
    for position, yaw in street_poses(world, args.poses, seed=0):
        origin = position + np.array([0.0, 0.0, 1.0])
        rotation = Rotation.from_quat(quat_from_yaw(yaw)).as_matrix().astype(np.float32)
        rays = np.ascontiguousarray(body @ rotation.T)

        def cast(part: slice, rays: np.ndarray = rays, origin: np.ndarray = origin) -> object:
            return caster.cast(origin, rays[part], camera.max_range)

        def halves(cast: Callable[[slice], object] = cast) -> None:
            other = thread_pool(2).submit(cast, slice(half, None))
            cast(slice(0, half))
            other.result()

        top = best_ms(lambda c=cast: c(slice(0, half)), args.repeats)
        bottom = best_ms(lambda c=cast: c(slice(half, None)), args.repeats)
        one = best_ms(lambda r=rays, o=origin: caster.cast(o, r, camera.max_range), args.repeats)
        split = best_ms(halves, args.repeats)
        dealt = best_ms(
            lambda r=rays, o=origin: caster.cast(o, r, camera.max_range, threads=2), args.repeats
        )
        print(
            f"  {top:8.2f} {bottom:12.2f} {one:12.2f} {split:13.2f} {dealt:12.2f}"
            f" {dealt / one:13.2f}"
        )


if __name__ == "__main__":
    main()
