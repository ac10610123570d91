"""What ``seminspect terrain graph`` reads: scans, saved clouds and point files.

A point file is moved to metres about a local origin (``mapping.local_frame``) and, when it
carries neither labels nor embeddings, labelled by the geometric path (``mapping.ground``);
both are recorded for ``summary.json``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from seminspect.cli._common import console

#: Prompts of labelled input, and of the geometric path (the labels it gives).
TERRAIN_DEFAULT, OBJECTS_DEFAULT = "sidewalk,grass,asphalt", "image of a tree,image of a car"
BARE_TERRAIN, BARE_OBJECTS = "ground", "object"
ASPRS_GROUND = 2
#: Object points are voxelised at most this coarsely in phase 2 (its default), and at half the
#: clustering radius on denser clouds, so that the voxel stays below the radius.
BARE_OBJECT_VOXEL = 0.15
_UNIT_WORDS = {"m": "metres", "ft": "international feet", "us-ft": "US survey feet"}


def load_cloud(inputs: list[Path], labels: list[Path], options: dict[str, Any], encoder, progress):
    """The phase-1 cloud; the fused KITTI labels when the input is scans (else ``None``); and
    what reading a point file adds to ``summary.json`` (its frame, the geometric path)."""
    from seminspect.core.errors import InvalidInputError
    from seminspect.mapping.formats.pointfiles import label_names_from_text
    from seminspect.mapping.formats.semantickitti import (
        fuse_kitti_scans,
        read_calib,
        read_poses,
        velodyne_poses,
    )
    from seminspect.mapping.ingest import cloud_from_point_data
    from seminspect.mapping.semantic_cloud import cloud_from_arrays, is_cloud_file, read_npz

    if all(path.suffix.lower() == ".bin" for path in inputs):
        _no_point_file_options(inputs[0], options)
        if len(labels) != len(inputs):
            raise InvalidInputError("give one --labels file per SemanticKITTI scan")
        poses = None
        if options["poses"] is not None or options["calib"] is not None:
            if options["poses"] is None or options["calib"] is None:
                raise InvalidInputError("--poses and --calib go together")
            tr = read_calib(options["calib"])["Tr"]
            poses = velodyne_poses(read_poses(options["poses"]), tr)
        task = progress.add_task("phase 1: fusing scans", total=len(inputs))
        scans = fuse_kitti_scans(
            list(zip(inputs, labels, strict=True)),
            poses,
            encoder,
            options["radius"],
            on_scan=lambda _: progress.advance(task),
        )
        return scans.cloud, scans, {}
    if len(inputs) != 1 or labels:
        raise InvalidInputError("give one cloud file (several inputs and --labels are for scans)")
    source = inputs[0]
    if source.suffix.lower() == ".npz":
        arrays = read_npz(source)
        if is_cloud_file(arrays):
            _no_point_file_options(source, options)
            cloud = cloud_from_arrays(source, arrays)
            if cloud.encoder != encoder.name:
                raise InvalidInputError(
                    f"{source} was embedded by {cloud.encoder!r}; pass --encoder {cloud.encoder}"
                )
            return cloud, None, {}
    data, extra = _point_file(source, options)
    names = label_names_from_text(options["label_names"]) if options["label_names"] else None
    return cloud_from_point_data(data, encoder, names, source), None, extra


def _no_point_file_options(source: Path, options: dict[str, Any]) -> None:
    """``--units`` and ``--labels-from`` concern point files, not scans or saved clouds."""
    from seminspect.core.errors import InvalidInputError

    for name in ("units", "labels_from"):
        if options[name] is not None:
            flag = "--" + name.replace("_", "-")
            raise InvalidInputError(f"{source}: {flag} is for point files, not scans or clouds")


def _point_file(source: Path, options: dict[str, Any]):
    """A point file in metres about its local origin, labelled by the geometric path when it
    carries neither labels nor embeddings; and the record of both for ``summary.json``."""
    from seminspect.core.errors import InvalidInputError
    from seminspect.mapping.formats.las import LasPointData, classification_labels
    from seminspect.mapping.formats.pointfiles import PointData, load_point_file
    from seminspect.mapping.ingest import label_bare_points
    from seminspect.mapping.local_frame import choose_units, to_local_frame

    loaded = load_point_file(source)
    las = loaded if isinstance(loaded, LasPointData) else None
    declared: tuple[str | None, str | None, str] = (None, None, "")
    if las is not None:
        declared = (las.unit, las.vertical_unit, las.unit_source)
    points, frame = to_local_frame(loaded.points, *choose_units(options["units"], *declared))
    _print_frame(source, frame)
    data = PointData(points, loaded.embeddings, loaded.labels, loaded.label_names)
    if options["labels_from"] is not None:
        if las is None:
            raise InvalidInputError(f"{source}: --labels-from classification needs a LAS file")
        data.labels, data.label_names = classification_labels(las, source)
    extra: dict[str, Any] = {"frame": frame.to_json()}
    if data.embeddings is None and data.labels is None:
        data, bare = label_bare_points(data, source=source)
        classes = las.classification if las is not None else None
        extra["geometric_path"] = _print_bare(source, bare, classes)
    return data, extra


def _print_frame(source: Path, frame) -> None:
    """One line when the coordinates were converted or moved (nothing for a local metric
    cloud)."""
    if frame.units == "m" and frame.vertical_units == "m" and not any(frame.origin_m):
        return
    vertical = "" if frame.vertical_units == frame.units else f", heights in {frame.vertical_units}"
    origin = ", ".join(f"{v:.0f}" for v in frame.origin_m)
    console.print(
        f"{source}: coordinates in {_UNIT_WORDS[frame.units]}{vertical} ({frame.units_from}); "
        f"local origin ({origin}) m subtracted, recorded in summary.json 'frame'",
        highlight=False,
        soft_wrap=True,
    )


def _print_bare(source: Path, bare, classes) -> dict[str, Any]:
    """The geometric path's line, and its record for ``summary.json`` (with the filter's
    errors against the file's own ground class, ASPRS 2, when it has one)."""
    from seminspect.mapping.ground import filter_errors

    counts = {name: int((bare.labels == code).sum()) for code, name in bare.names.items()}
    clusters = int(bare.objects.max()) + 1 if bare.objects.size else 0
    console.print(
        f"{source}: no labels or embeddings; geometric path: progressive morphological ground "
        f"filter (cell {bare.cell:.2f} m from the median spacing {bare.spacing:.2f} m): "
        f"{counts['ground']:,} ground, {counts['object']:,} object points in {clusters} "
        f"clusters, {counts['outlier']:,} outliers skipped",
        highlight=False,
        soft_wrap=True,
    )
    record: dict[str, Any] = {
        "filter": "progressive morphological (Zhang et al. 2003)",
        "spacing": bare.spacing,
        "cell": bare.cell,
        "object_eps": bare.eps,
        "points": counts,
        "clusters": clusters,
        "seconds": bare.seconds,
    }
    if classes is not None and bool((classes == ASPRS_GROUND).any()):
        errors = filter_errors(bare.is_ground, classes == ASPRS_GROUND)
        record["errors_against_class_2"] = errors
        console.print(
            f"{source}: against the file's ground class: type I {100 * errors['type_1']:.1f} %, "
            f"type II {100 * errors['type_2']:.1f} %, total {100 * errors['total']:.1f} %",
            highlight=False,
            soft_wrap=True,
        )
    return record


def check_labels_from(labels_from: str | None) -> None:
    from seminspect.core.errors import InvalidInputError

    if labels_from not in (None, "classification"):
        raise InvalidInputError(f"--labels-from takes 'classification', got {labels_from!r}")


def task_prompts(terrain: str | None, objects: str | None, *, bare: bool):
    """The task's prompts: as given, else the labels of the geometric path for a bare cloud,
    else the defaults of labelled clouds."""
    from seminspect.graphs.terrain.prompting import TaskPrompts

    if terrain is None:
        terrain = BARE_TERRAIN if bare else TERRAIN_DEFAULT
    if objects is None:
        objects = BARE_OBJECTS if bare else OBJECTS_DEFAULT
    return TaskPrompts.parse(terrain, objects)


def bare_object_params(extra: dict[str, Any], given: dict[str, Any]) -> dict[str, Any]:
    """Phase 2's object clustering on the geometric path: the radius of the path's own
    clustering (it follows the cloud's spacing), unless ``--param`` sets it."""
    record = extra.get("geometric_path")
    if record is None:
        return given
    eps = record["object_eps"]
    derived = {"object_eps": eps, "object_voxel": min(BARE_OBJECT_VOXEL, eps / 2)}
    return {**derived, **given}
