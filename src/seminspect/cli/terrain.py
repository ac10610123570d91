"""``seminspect terrain``: task-driven terrain scene graphs from metric-semantic clouds (001)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from seminspect.cli._common import console, labelled, writable_directory, writable_file
from seminspect.cli.terrain_input import (
    OBJECTS_DEFAULT,
    TERRAIN_DEFAULT,
    bare_object_params,
    check_labels_from,
    load_cloud,
    task_prompts,
)

if TYPE_CHECKING:
    from seminspect.graphs.terrain.evaluate import ObjectQuality

app = typer.Typer(no_args_is_help=True, help="Terrain-aware, task-driven outdoor scene graphs.")

_GRAPH_HELP = """Build the task-driven scene graph (001 Sec III-B) of a cloud or scans.


INPUT is a .ply/.pcd/.npz/.las/.laz cloud with per-point embeddings or labels, a semantic cloud
saved by seminspect, or SemanticKITTI .bin scans with --labels (one per scan, same order). A
cloud with neither (a bare LiDAR survey) takes the geometric path: a ground filter and object
clustering label it 'ground' and 'object', and the prompts default to those two."""

# Options that do not fit on the command's line, and those both commands share.
_ENCODER_OPTION = typer.Option(
    "minilm",
    "--encoder",
    help="Registered encoder name, or package.module:factory, which imports that module "
    "and runs the factory (only name code you trust).",
)
_RADIUS_OPTION = typer.Option(0.15, help="Association radius of scan points to map points [m].")
_OBJECTS_OPTION = typer.Option(
    None, help=f"Object prompts, comma-separated [default: {OBJECTS_DEFAULT}; bare: object]."
)
_TERRAIN_OPTION = typer.Option(
    None, help=f"Terrain prompts, comma-separated [default: {TERRAIN_DEFAULT}; bare: ground]."
)
_UNITS_OPTION = typer.Option(
    None,
    "--units",
    help="Units of the point file's coordinates: m, ft (0.3048 m) or us-ft (1200/3937 m) "
    "[default: the LAS header's, else m].",
)
_LABELS_FROM_OPTION = typer.Option(
    None,
    "--labels-from",
    help="'classification': take a LAS file's ASPRS classes as labels instead of the "
    "geometric path.",
)
_CLOUD_LABEL_NAMES_OPTION = typer.Option(
    None, help="Names of a cloud's integer labels, e.g. '0=grass,1=car'."
)
_EVALUATE_OPTION = typer.Option(
    False,
    help="Score against ground truth: SemanticKITTI instance labels, or the simulated "
    "world a 'terrain map' cloud came from.",
)
_WORLD_OPTION = typer.Option(
    "outdoor", help="World with a drive path: a built-in name or a user world folder."
)
_SCENARIO_OPTION = typer.Option(
    None, "--scenario", "-s", help="World scenario (the world's default when omitted)."
)
_BAG_OPTION = typer.Option(
    None, "--bag", help="Map a ROS1/ROS2 bag's labelled clouds instead of a simulated world."
)
_BAG_LABEL_NAMES_OPTION = typer.Option(
    None,
    help="Names of the bag's labels, e.g. '0=grass,1=car' (default: the bag's own names "
    "topic, else SemanticKITTI's table).",
)


def _param_overrides(items: list[str], cell_size: float | None) -> dict[str, Any]:
    from seminspect.core.errors import InvalidInputError

    values: dict[str, Any] = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep:
            raise InvalidInputError(f"--param takes NAME=VALUE, got {item!r}")
        try:
            values[key.strip()] = float(value) if "." in value or "e" in value else int(value)
        except ValueError:
            raise InvalidInputError(f"--param {key} needs a number, got {value!r}") from None
    if cell_size is not None:
        values["cell_size"] = cell_size
    return values


def _positive_radius(radius: float) -> None:
    import math

    from seminspect.core.errors import InvalidInputError

    if not (math.isfinite(radius) and radius > 0):
        raise InvalidInputError(f"--radius must be a positive number of metres, got {radius}")


def _encoder(name: str, noise: float, seed: int):
    """A registered or plug-in encoder; a caption encoder gets ``noise`` per view."""
    import dataclasses

    from seminspect.perception.encoders import CaptionEncoder, make_encoder

    encoder = make_encoder(name)
    if noise and isinstance(encoder, CaptionEncoder):
        encoder = dataclasses.replace(encoder, noise=noise, seed=seed)
    return encoder


def _kitti_quality(build, fused, encoder) -> dict[str, ObjectQuality]:
    """Object precision/recall against the scans' own instance labels.

    A prompt is matched against every class of the label table, so 'trunk' is the trunk class;
    only SemanticKITTI's "things" carry instance ids, and a prompt naming any other class is
    reported unscored rather than scored against the nearest thing.
    """
    from seminspect.graphs.terrain.evaluate import (
        ObjectQuality,
        match_boxes,
        match_class,
        predicted_boxes,
    )
    from seminspect.mapping.formats.semantickitti import instance_boxes, label_table

    table = label_table()
    things = table.thing_classes()
    # every label name whose points train as a thing ('moving-car' is a car) -> that class id
    ids = {
        name: table.learning_map[raw]
        for raw, name in table.names.items()
        if table.learning_map[raw] in things
    }
    classes = sorted(set(table.names.values()))
    report: dict[str, ObjectQuality] = {}
    for prompt in build.scene.prompts.objects:
        match = match_class(encoder, prompt, classes, build.scene.calibration.objects)
        if match.truth not in ids:
            unscored = None
            if match.truth is not None:
                unscored = f"SemanticKITTI has no instances of {match.truth!r}"
            report[prompt] = ObjectQuality(match, unscored=unscored)
            continue
        boxes = instance_boxes(
            fused.points, fused.semantic, fused.instance, ids[match.truth], min_points=1
        )
        scores = match_boxes(predicted_boxes(build.scene, prompt), boxes, threshold=0.3)
        report[prompt] = ObjectQuality(match, scores)
    return report


def _require_truth(cloud, fused) -> None:
    """``--evaluate`` needs instance-labelled scans or a cloud that records its world."""
    from seminspect.core.errors import InvalidInputError

    if fused is None and "world" not in cloud.source:
        raise InvalidInputError(
            "--evaluate needs SemanticKITTI scans with instance labels "
            "or a cloud from 'seminspect terrain map'"
        )


def _quality(build, cloud, fused, encoder) -> dict[str, Any]:
    """Scores against the scans' instance labels, or against the simulated world's truth, as
    ``summary.json`` records them."""
    from seminspect.missions.terrain.mapping import evaluate_on_world, source_world

    if fused is not None:
        return {p: q.to_json() for p, q in _kitti_quality(build, fused, encoder).items()}
    world = source_world(cloud)
    assert world is not None, "the command checks for a source world before building"
    return evaluate_on_world(build, world, encoder).to_json()


def _calibration(encoder_name: str, terrain: float | None, objects: float | None):
    """The encoder's calibrated thresholds, with the ones given on the command line."""
    import dataclasses

    from seminspect.perception.encoders import calibration_for

    calibration = calibration_for(encoder_name)
    if terrain is None and objects is None:
        return calibration
    return dataclasses.replace(
        calibration,
        terrain=calibration.terrain if terrain is None else terrain,
        objects=calibration.objects if objects is None else objects,
    )


def _stage_reporter(progress) -> Callable[[str], None]:
    """A progress task for phase 2's stages, advanced by the returned callback."""
    stages = progress.add_task("phase 2", total=5)

    def on_stage(name: str) -> None:
        progress.update(stages, description=f"phase 2: {name}", advance=1)

    return on_stage


def _write_outputs(out: Path, build, cloud, progress) -> None:
    from seminspect.graphs.terrain.io import save_terrain_graph, write_graphml
    from seminspect.report.terrain import (
        plot_classified_cloud,
        plot_gvd_stages,
        plot_layered_graph,
        plot_place_layer,
    )

    task = progress.add_task("writing graph and pictures", total=4 + len(build.places.gvd))
    save_terrain_graph(out / "graph.json", build.scene, layer1_file="layer1.npz")
    write_graphml(out / "graph.graphml", build.scene)
    progress.advance(task)
    plot_classified_cloud(out / "classified_cloud.png", cloud.points, build.cloud_classes,
                          build.scene.prompts)  # fmt: skip
    progress.advance(task)
    for index, (terrain, gvd) in enumerate(build.places.gvd.items()):
        plot_gvd_stages(out / f"gvd_{index}_{_slug(terrain)}.png", gvd, terrain)
        progress.advance(task)
    plot_place_layer(out / "places.png", build)
    progress.advance(task)
    plot_layered_graph(out / "layers.png", build)
    progress.advance(task)


def _slug(text: str) -> str:
    return "".join(ch if ch.isalnum() else "_" for ch in text).strip("_") or "terrain"


def _write_summary(
    out: Path, cloud, build, quality: dict[str, Any] | None, extra: dict[str, Any] | None = None
) -> dict[str, Any]:
    """``summary.json`` and ``report.html`` of a graph directory; returns the summary."""
    import json

    from seminspect.core.io import atomic_write_text
    from seminspect.report.html import write_terrain_report

    summary = {
        "cloud_points": len(cloud),
        **build.scene.summary(),
        "seconds": build.timings,
        "quality": quality,
        **(extra or {}),
    }
    atomic_write_text(out / "summary.json", json.dumps(summary, indent=2) + "\n")
    write_terrain_report(out)
    return summary


def _print_graph_summary(out: Path, summary: dict[str, Any]) -> None:
    import json

    console.print(
        labelled("terrain graph", "bold", f"written to {out} (open report.html in a browser)")
    )
    hidden = ("seconds", "frame", "geometric_path")
    console.print_json(json.dumps({k: v for k, v in summary.items() if k not in hidden}))


@app.command("graph", help=_GRAPH_HELP)
def graph(
    inputs: list[Path] = typer.Argument(..., help="Cloud file, or SemanticKITTI .bin scans."),
    out: Path = typer.Option(..., "--out", help="Directory for the graph, summary and pictures."),
    terrain: str | None = _TERRAIN_OPTION,
    objects: str | None = _OBJECTS_OPTION,
    labels: list[Path] = typer.Option([], "--labels", help="SemanticKITTI .label, one per scan."),
    poses: Path | None = typer.Option(None, help="KITTI poses.txt (fuses several scans)."),
    calib: Path | None = typer.Option(None, help="KITTI calib.txt (with --poses)."),
    label_names: str | None = _CLOUD_LABEL_NAMES_OPTION,
    encoder_name: str = _ENCODER_OPTION,
    noise: float = typer.Option(0.0, help="Caption noise per view (labelled input)."),
    seed: int = typer.Option(0, help="Seed of the caption noise."),
    radius: float = _RADIUS_OPTION,
    terrain_threshold: float | None = typer.Option(None, help="Override the terrain threshold."),
    object_threshold: float | None = typer.Option(None, help="Override α, the object threshold."),
    cell_size: float | None = typer.Option(
        None,
        help="Terrain grid cell size [m] (default 0.5; three point spacings for clouds "
        "sparser than 0.4 m).",
    ),
    param: list[str] = typer.Option([], help="Any graph parameter as NAME=VALUE (repeatable)."),
    evaluate: bool = _EVALUATE_OPTION,
    units: str | None = _UNITS_OPTION,
    labels_from: str | None = _LABELS_FROM_OPTION,
) -> None:
    from rich.progress import Progress

    from seminspect.graphs.terrain.params import make_terrain_params
    from seminspect.graphs.terrain.scene_graph import build_terrain_graph
    from seminspect.mapping.local_frame import check_units

    writable_directory(out)
    _positive_radius(radius)
    check_labels_from(labels_from)
    given = _param_overrides(param, cell_size)
    make_terrain_params(given)  # a bad --param fails before the cloud is read
    encoder = _encoder(encoder_name, noise, seed)
    calibration = _calibration(encoder.name, terrain_threshold, object_threshold)
    options = {"poses": poses, "calib": calib, "radius": radius, "label_names": label_names,
               "units": check_units(units), "labels_from": labels_from}  # fmt: skip
    with Progress(console=console, transient=True) as progress:
        cloud, fused, extra = load_cloud(inputs, labels, options, encoder, progress)
        prompts = task_prompts(terrain, objects, bare="geometric_path" in extra)
        params = make_terrain_params(bare_object_params(extra, given))
        if evaluate:
            _require_truth(cloud, fused)
        on_stage = _stage_reporter(progress)
        build = build_terrain_graph(
            cloud, prompts, encoder, params=params, calibration=calibration, on_stage=on_stage
        )
        quality = _quality(build, cloud, fused, encoder) if evaluate else None
        _write_outputs(out, build, cloud, progress)
    if build.choice is not None and build.choice.derived:  # say what the spacing changed
        console.print(labelled("parameters:", "bold", build.choice.describe()), soft_wrap=True)
    _print_graph_summary(out, _write_summary(out, cloud, build, quality, extra))


@app.command("route")
def route(
    graph_file: Path = typer.Argument(..., help="graph.json written by 'terrain graph'."),
    start: str = typer.Option(..., "--from", help="Start place id, e.g. place-3."),
    goal: str = typer.Option(..., "--to", help="Goal place id."),
    terrain: str | None = typer.Option(None, help="Terrain types allowed, comma-separated."),
) -> None:
    """Shortest route between two places over the chosen terrain types."""
    from seminspect.graphs.terrain.io import load_terrain_graph
    from seminspect.graphs.terrain.navigation import shortest_route

    scene = load_terrain_graph(graph_file)
    allowed = [t.strip() for t in terrain.split(",") if t.strip()] if terrain else None
    places, length = shortest_route(scene, start, goal, allowed)
    console.print(f"{len(places)} places, {length:.1f} m: " + " -> ".join(places))


@app.command("map")
def map_command(
    out: Path = typer.Option(..., "--out", help="The semantic cloud to write (.npz)."),
    world: str = _WORLD_OPTION,
    scenario: str | None = _SCENARIO_OPTION,
    seed: int = typer.Option(0, help="Seed of the world and of the caption noise."),
    encoder_name: str = _ENCODER_OPTION,
    noise: float = typer.Option(0.3, help="Caption noise per view (caption encoders)."),
    spacing: float = typer.Option(1.0, help="Metres driven between frames."),
    radius: float = _RADIUS_OPTION,
    bag: Path | None = _BAG_OPTION,
    cloud_topic: str = typer.Option("/points", help="PointCloud2 topic of the bag."),
    odom_topic: str = typer.Option("/odom", help="Odometry topic of the bag (the cloud's pose)."),
    labels_field: str = typer.Option("label", help="Integer label field of the bag's clouds."),
    label_names: str | None = _BAG_LABEL_NAMES_OPTION,
) -> None:
    """Phase 1 (001 Sec III-A) in the simulator: drive a world's path, fuse LiDAR and camera.

    Writes the metric-semantic cloud that 'seminspect terrain graph' reads; the cloud remembers
    its world, so 'terrain graph CLOUD --evaluate' scores the graph against that world. With
    --bag, the cloud is fused from a recorded bag's labelled PointCloud2 and Odometry instead.
    """
    if bag is not None:
        bag_topics = (cloud_topic, odom_topic, labels_field, label_names)
        _map_bag(bag, bag_topics, out, _encoder(encoder_name, noise, seed), radius)
        return
    from seminspect.mapping.semantic_cloud import save_cloud
    from seminspect.missions.terrain.mapping import make_mapping_params
    from seminspect.worlds import open_world

    writable_file(out, (".npz",))
    params = make_mapping_params({"spacing": spacing, "radius": radius})
    site = open_world(world, scenario, seed)
    run = _drive_with_progress(site, _encoder(encoder_name, noise, seed), params)
    save_cloud(out, run.cloud)
    _print_mapping(out, run)


def _drive_with_progress(site, encoder, params):
    """Phase 1 in the simulator, with a frame counter."""
    from rich.progress import MofNCompleteColumn, Progress, TimeElapsedColumn

    from seminspect.missions.terrain.mapping import map_world

    columns = (*Progress.get_default_columns()[:2], MofNCompleteColumn(), TimeElapsedColumn())
    with Progress(*columns, console=console, transient=True) as progress:
        task = progress.add_task("phase 1: scanning and fusing", total=None)
        return map_world(
            site,
            encoder,
            params=params,
            on_frame=lambda done, total: progress.update(task, completed=done, total=total),
        )


def _print_mapping(out: Path, run) -> None:
    seconds = run.seconds
    console.print(
        labelled(
            "semantic cloud",
            "bold",
            f"written to {out}: {len(run.cloud):,} points from "
            f"{run.frames} frames over {run.distance:.0f} m, {run.cloud.counts.mean():.1f} views "
            f"per point; {seconds['total']:.1f} s ({1000 * seconds['total'] / run.frames:.0f} ms "
            f"per frame: sensors {seconds['sensors']:.1f} s, segments {seconds['segments']:.1f} s, "
            f"fusion {seconds['fusion']:.1f} s)",
        ),
        highlight=False,
        soft_wrap=True,
    )


def _map_bag(bag: Path, topics: tuple[str, str, str, str | None], out: Path, encoder, radius):
    """001's metric-semantic cloud from a bag's labelled clouds, one view per cloud."""
    from rich.progress import Progress, TimeElapsedColumn

    from seminspect.mapping.formats.pointfiles import label_names_from_text
    from seminspect.mapping.formats.rosbag import fuse_bag, read_bag_scans, read_label_names
    from seminspect.mapping.semantic_cloud import save_cloud

    cloud_topic, odom_topic, labels_field, names_text = topics
    names = label_names_from_text(names_text) if names_text else read_label_names(bag)
    columns = (*Progress.get_default_columns()[:1], TimeElapsedColumn())
    with Progress(*columns, console=console, transient=True) as progress:
        task = progress.add_task("phase 1: fusing the bag's clouds", total=None)
        scans = read_bag_scans(bag, cloud_topic, odom_topic, labels_field)
        cloud = fuse_bag(
            scans,
            names,
            encoder,
            radius,
            on_scan=lambda done: progress.update(task, description=f"fused {done} clouds"),
        )
    cloud.source = {"bag": str(bag), "cloud_topic": cloud_topic, "odom_topic": odom_topic}
    save_cloud(out, cloud)
    console.print(
        labelled(
            "semantic cloud",
            "bold",
            f"written to {out}: {len(cloud):,} points from {bag}, "
            f"{cloud.counts.mean():.1f} views per point",
        ),
        highlight=False,
        soft_wrap=True,
    )
