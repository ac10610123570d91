"""The geometric path for bare clouds (``mapping.ground``) against the ground truth of real data.

- ISPRS filter test (15 samples, ``isprs_samples_with_ground_labels.npz``): type I, type II and
  total error per sample (Sithole & Vosselman 2004, Sec 4.1).
- Autzen (``autzen_trim.laz``, read by ``mapping.formats.las`` in its declared feet): the same
  errors against its ASPRS ground class 2.
- ``pcl_outdoor``: the objects found on ``car6.pcd`` (two parked cars) and
  ``min_cut_segmentation_tutorial.pcd`` (three), with their box sizes.
- ``--points N``: a LAZ of N points tiled from Autzen (seeded jitter, written with laspy and
  lazrs to a temporary directory) through every stage up to the terrain graph, with the seconds
  of each stage and the peak RSS; ``--encoder`` picks the encoder (MiniLM by default).

Prints figures and writes nothing unless ``--laz-out`` keeps the tiled file. Needs
``../shared/data`` (or ``$SEMINSPECT_SHARED_DATA``).

Run: ``.venv/bin/python bench/ground_filter.py [--points 1000000]``.
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from seminspect.core.rng import make_rng
from seminspect.mapping.formats.las import read_las
from seminspect.mapping.formats.pointfiles import PointData, load_point_file
from seminspect.mapping.ground import (
    GroundFilterParams,
    filter_errors,
    height_above_ground,
    label_bare_cloud,
)
from seminspect.mapping.local_frame import choose_units, to_local_frame

SAMPLES = ("11", "12", "21", "22", "23", "24", "31", "41", "42", "51", "52", "53", "54", "61",
           "71")  # fmt: skip
CLASS_2_CELL = 2.0  # [m] grid of the class-2 surface that class-1 heights are measured from
CARS = {"car6.pcd": 2, "min_cut_segmentation_tutorial.pcd": 3}


def shared_data() -> Path:
    for candidate in (os.environ.get("SEMINSPECT_SHARED_DATA"), "../shared/data"):
        if candidate and Path(candidate).is_dir():
            return Path(candidate)
    sys.exit("needs ../shared/data or $SEMINSPECT_SHARED_DATA")


def isprs(data: Path, params: GroundFilterParams) -> None:
    arrays = np.load(data / "isprs_filtertest_terrain" / "isprs_samples_with_ground_labels.npz")
    print("ISPRS filter test: errors of the progressive morphological filter [%]")
    print(f"{'sample':>7} {'points':>7} {'spacing':>8} {'type I':>7} {'type II':>8} {'total':>6}")
    totals = []
    for sample in SAMPLES:
        points = arrays[f"samp{sample}_xyz"].astype(np.float64)
        points -= np.floor(points.min(axis=0))  # the local origin, as the CLI takes it
        bare = label_bare_cloud(points, params)
        errors = filter_errors(bare.is_ground, arrays[f"samp{sample}_is_ground"])
        totals.append(errors["total"])
        print(
            f"{'samp' + sample:>7} {len(points):>7} {bare.spacing:>7.2f}m "
            f"{100 * errors['type_1']:>7.2f} {100 * errors['type_2']:>8.2f} "
            f"{100 * errors['total']:>6.2f}"
        )
    print(f"mean total error {100 * np.mean(totals):.2f} % (target <= 10 %)\n")


def autzen(data: Path, params: GroundFilterParams) -> None:
    las = read_las(data / "aerial_lidar_las" / "autzen_trim.laz")
    points, frame = to_local_frame(las.points, *choose_units(None, las.unit, las.vertical_unit,
                                                             las.unit_source))  # fmt: skip
    bare = label_bare_cloud(points, params)
    assert las.classification is not None
    errors = filter_errors(bare.is_ground, las.classification == 2)
    print(
        f"Autzen ({len(points):,} points, units {frame.units} {frame.units_from}, spacing "
        f"{bare.spacing:.2f} m): type I {100 * errors['type_1']:.2f} %, type II "
        f"{100 * errors['type_2']:.2f} %, total {100 * errors['total']:.2f} % against class 2"
    )
    # Class 1 is "unclassified", not "object": its height above the class-2 surface tells
    # the points that are ground left unclassified from those that stand above it.
    height = height_above_ground(points, las.classification == 2, CLASS_2_CELL)
    unclassified = las.classification == 1
    for name, part in (
        ("within 0.3 m of", np.abs(height) <= 0.3),
        ("over 0.5 m above", height > 0.5),
    ):
        chosen = unclassified & part
        share = float(bare.is_ground[chosen].mean())
        print(f"  class-1 points {name} the class-2 surface: {int(chosen.sum()):,}, "
              f"{100 * share:.2f} % taken as ground")  # fmt: skip
    print()


def parked_cars(data: Path, params: GroundFilterParams) -> None:
    for name, cars in CARS.items():
        points = load_point_file(data / "pcl_outdoor" / name).points
        bare = label_bare_cloud(points, params)
        found = bare.object_sizes(points)
        sizes = ", ".join(
            f"{n} pts {size[0]:.1f}x{size[1]:.1f}x{size[2]:.1f} m" for n, size in found[:6]
        )
        print(
            f"{name}: {cars} cars; spacing {bare.spacing:.3f} m, {int(bare.is_ground.sum()):,} "
            f"ground of {len(points):,}; {len(found)} objects: {sizes}"
        )
    print()


def tiled_autzen(data: Path, points: int, target: Path) -> None:
    """Autzen tiled side by side (each tile seeded-jittered by 0.05 ft) to ``points`` points."""
    import laspy

    source = laspy.read(data / "aerial_lidar_las" / "autzen_trim.laz")
    xyz = np.column_stack([source.x, source.y, source.z])
    extent = np.ptp(xyz, axis=0)
    rng = make_rng(0, "bench", "ground-filter", "tiles")
    tiles = -(-points // len(xyz))
    side = int(np.ceil(np.sqrt(tiles)))
    parts, classes = [], []
    for tile in range(tiles):
        shift = np.array([tile % side * extent[0], tile // side * extent[1], 0.0])
        parts.append(xyz + shift + rng.normal(0, 0.05, xyz.shape))
        classes.append(np.asarray(source.classification))
    out = laspy.LasData(laspy.LasHeader(point_format=3, version="1.2"))
    out.header.scales = source.header.scales
    out.header.offsets = source.header.offsets
    out.header.vlrs = source.header.vlrs
    cloud = np.vstack(parts)[:points]
    out.x, out.y, out.z = cloud[:, 0], cloud[:, 1], cloud[:, 2]
    out.classification = np.concatenate(classes)[:points]
    out.write(target)


def performance(data: Path, points: int, encoder_name: str, keep: Path | None) -> None:
    from seminspect.cli.terrain_input import bare_object_params
    from seminspect.graphs.terrain.params import make_terrain_params
    from seminspect.graphs.terrain.prompting import TaskPrompts
    from seminspect.graphs.terrain.scene_graph import build_terrain_graph
    from seminspect.mapping.ingest import cloud_from_point_data, label_bare_points
    from seminspect.perception.encoders import calibration_for, make_encoder

    with tempfile.TemporaryDirectory() as folder:
        target = keep or Path(folder) / "tiled.laz"
        start = time.perf_counter()
        tiled_autzen(data, points, target)
        print(f"wrote {points:,} points to {target} in {time.perf_counter() - start:.1f} s")
        seconds: dict[str, float] = {}
        start = time.perf_counter()
        las = read_las(target)
        seconds["read LAZ"] = time.perf_counter() - start
        start = time.perf_counter()
        units = choose_units(None, las.unit, las.vertical_unit, las.unit_source)
        local, _ = to_local_frame(las.points, *units)
        seconds["units + origin"] = time.perf_counter() - start
        start = time.perf_counter()
        labelled, bare = label_bare_points(PointData(local), source=target)
        seconds["geometric path"] = time.perf_counter() - start
        start = time.perf_counter()
        encoder = make_encoder(encoder_name)  # the model loads on first use, just below
        cloud = cloud_from_point_data(labelled, encoder, source=target)
        seconds["encoder + labels"] = time.perf_counter() - start
        start = time.perf_counter()
        # phase 2's object clustering takes the geometric path's radius, as the command does
        params = make_terrain_params(
            bare_object_params({"geometric_path": {"object_eps": bare.eps}}, {})
        )
        prompts = TaskPrompts.parse("ground", "object")
        calibration = calibration_for(encoder.name)
        build = build_terrain_graph(cloud, prompts, encoder, params=params, calibration=calibration)
        seconds["phase 2"] = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2
    print(f"{points:,} points: {sum(seconds.values()):.1f} s to the graph, peak RSS {peak:.2f} GB")
    for stage, value in {**seconds, **{f"  {k}": v for k, v in bare.seconds.items()}}.items():
        print(f"  {stage:<18} {value:6.2f} s")
    for stage, value in build.timings.items():
        print(f"  phase 2 {stage:<10} {value:6.2f} s")
    print(f"  graph: {build.scene.summary()}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, help="also time a tiled Autzen LAZ of N points")
    parser.add_argument("--encoder", default="minilm", help="encoder of the --points run")
    parser.add_argument("--laz-out", type=Path, help="keep the tiled LAZ at this path")
    parser.add_argument("--skip-checks", action="store_true", help="only the --points run")
    args = parser.parse_args()
    data = shared_data()
    params = GroundFilterParams()
    if not args.skip_checks:
        isprs(data, params)
        autzen(data, params)
        parked_cars(data, params)
    if args.points:
        performance(data, args.points, args.encoder, args.laz_out)


if __name__ == "__main__":
    main()
