"""Phase 1 of 001 in the simulator: time per frame and in total, by step.

Drives the ``outdoor`` world's path (``block`` by default, seed 0) with the default rig (a
640 x 400 camera, a 128 x 1024 LiDAR), 1 m between frames, MiniLM captions with 0.3 noise per
view, and reports the time spent ray casting (sensors), segmenting and embedding (segments) and
fusing, per frame and in total. As a coarse check that fusion cost does not grow with the map, it
also compares the mean time of a frame in the first and in the last quarter of the drive (other
parts of the world, with a map several times larger).

Run: ``.venv/bin/python bench/terrain_mapping.py [--scenario small]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from seminspect.missions.terrain.mapping import map_world
from seminspect.perception.encoders import CaptionEncoder, MiniLMTextEncoder
from seminspect.worlds import generate_world


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default="block")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    world = generate_world("outdoor", args.scenario, seed=args.seed)
    encoder = CaptionEncoder(MiniLMTextEncoder(), noise=0.3, seed=args.seed)
    encoder.encode_labels(["grass"])  # load the model outside the timed drive
    world.raycaster  # noqa: B018 - build the Embree scene outside the timed drive
    stamps: list[float] = []
    run = map_world(world, encoder, on_frame=lambda *_: stamps.append(time.perf_counter()))
    per_frame = np.diff(stamps)
    quarter = max(1, len(per_frame) // 4)
    seconds = run.seconds
    print(f"outdoor {args.scenario}, seed {args.seed}: {run.frames} frames, {run.distance:.0f} m")
    print(f"cloud: {len(run.cloud):,} points, {run.cloud.counts.mean():.1f} views per point")
    for step in ("sensors", "segments", "fusion", "total"):
        ms = 1000 * seconds[step] / run.frames
        print(f"  {step:<9} {seconds[step]:7.1f} s  {ms:6.1f} ms per frame")
    first, last = per_frame[:quarter].mean(), per_frame[-quarter:].mean()
    print(
        f"frame time, first quarter {1000 * first:.1f} ms, last quarter {1000 * last:.1f} ms "
        f"(ratio {last / first:.2f})"
    )


if __name__ == "__main__":
    main()
