"""``seminspect mission``: run an xFLIE inspection mission and show where the results are."""

from __future__ import annotations

import contextlib
import signal
from enum import Enum
from pathlib import Path

import typer

from seminspect.cli._common import (
    console,
    err_console,
    existing_outputs,
    exit_stopped,
    labelled,
    open_live_view,
    view_options,
    writable_directory,
)


class ModeChoice(str, Enum):
    ground = "ground"
    aerial = "aerial"


class NoiseChoice(str, Enum):
    ideal = "ideal"
    realistic = "realistic"


class PlannerChoice(str, Enum):
    hierarchical = "hierarchical"
    volumetric = "volumetric"
    frontier = "frontier"


# The command's options, declared here so that its signature reads as a list of names.
_WORLD_OPTION = typer.Option(
    "city",
    "--world",
    "-w",
    help="Built-in world (seminspect world list), or a user world: a folder with a mesh and "
    "its labels file, as 'seminspect world export' writes.",
)
_SCENARIO_OPTION = typer.Option(
    None, "--scenario", "-s", help="Scenario of the world (default: the world's; city: medium)."
)
_SEED_OPTION = typer.Option(0, "--seed", help="Seed of the world, sensors and robot.", min=0)
_PRESET_OPTION = typer.Option(
    None,
    "--preset",
    help="urban-simulated, urban-experimental or collapsed-buildings "
    "(000 Tables 1-2); default: the world's.",
)
_MODE_OPTION = typer.Option(None, "--mode", help="ground or aerial; default: the world's.")
_NOISE_OPTION = typer.Option(NoiseChoice.realistic, "--noise", help="Sensor noise preset.")
_PLANNER_OPTION = typer.Option(
    PlannerChoice.hierarchical,
    "--planner",
    help="hierarchical (3DLSG, the default), volumetric (the paper's baseline) or frontier "
    "(pure exploration that never inspects: 000 Table 6's exploration baseline).",
)
_BUDGET_OPTION = typer.Option(
    None, "--budget", help="Time budget in simulated seconds (default: 000 Sec VII-D's).", min=1
)
_CARVING_SPACING_OPTION = typer.Option(
    None,
    "--carving-spacing",
    help="Approximate, faster mapping: near the sensor only rays this many cells apart "
    "carve free space (default: every ray).",
    min=0.01,
    max=4.0,
)
_OUT_OPTION = typer.Option(None, "--out", "-o", help="Run directory (default: runs/<name>).")
_QUERY_OPTION = typer.Option(
    [], "--query", "-q", help="Operator query answered after the mission (repeatable)."
)
_PICTURES_OPTION = typer.Option(True, "--pictures/--no-pictures", help="Draw the run's pictures.")
_RESUME_OPTION = typer.Option(
    None,
    "--resume",
    help="Finish a run that was interrupted, failed or killed: run its configuration again "
    "from the start into its directory (missions are deterministic).",
)
_BAG_OPTION = typer.Option(
    None, "--bag", help="Replay the run's LiDAR stream into this new ROS2 bag (directory)."
)
_RECORD_MCAP_OPTION = typer.Option(
    False,
    "--record-mcap",
    help="When the mission ends, write run.mcap into the run directory: its poses, LiDAR, "
    "camera, 3DLSG and events as ROS 2 messages, for Foxglove (File > Open local file).",
)
_VIEW_OPTION, _VIEW_PORT_OPTION = view_options("the mission")
_DETECTOR_OPTION = typer.Option(
    "truth",
    "--detector",
    help="What segments the camera's frames: truth (the simulator's labels with the noise "
    "preset's faults), a model 'seminspect perception export' wrote (.onnx), or an "
    "instance-segmentation model in ONNX with YOLOv8-seg's outputs (.onnx with --class-map).",
)
_CLASS_MAP_OPTION = typer.Option(
    None,
    "--class-map",
    help="With an ONNX --detector: the JSON file naming each model class as a seminspect "
    'label ({"instance": {"0": "car"}, "part": {...}, "ignore": [...]}).',
)
_FEATURES_OPTION = typer.Option(
    None,
    "--features",
    help="Parts recorded as features, comma-separated (default: every part the world's "
    "targets carry besides body, roof and wall).",
)
_ROBOTS_OPTION = typer.Option(
    None,
    "--robots",
    help="A team sharing one 3DLSG: 'explorer,inspector' (default: one robot does both).",
)


def app(
    ctx: typer.Context,
    world: str = _WORLD_OPTION,
    scenario: str | None = _SCENARIO_OPTION,
    seed: int = _SEED_OPTION,
    preset: str | None = _PRESET_OPTION,
    mode: ModeChoice | None = _MODE_OPTION,
    noise: NoiseChoice = _NOISE_OPTION,
    planner: PlannerChoice = _PLANNER_OPTION,
    budget: float | None = _BUDGET_OPTION,
    carving_spacing: float | None = _CARVING_SPACING_OPTION,
    out: Path | None = _OUT_OPTION,
    query: list[str] = _QUERY_OPTION,
    pictures: bool = _PICTURES_OPTION,
    resume: Path | None = _RESUME_OPTION,
    bag: Path | None = _BAG_OPTION,
    record_mcap: bool = _RECORD_MCAP_OPTION,
    robots: str | None = _ROBOTS_OPTION,
    features: str | None = _FEATURES_OPTION,
    view: bool = _VIEW_OPTION,
    view_port: int = _VIEW_PORT_OPTION,
    detector: str = _DETECTOR_OPTION,
    class_map: Path | None = _CLASS_MAP_OPTION,
) -> None:
    """Explore a site, inspect every target level by level and build its 3DLSG (paper 000).

    Writes a run directory with the graph, metrics, a summary, the trajectory and pictures.
    Ctrl-C and SIGTERM stop the mission and leave a valid run directory (exit codes 130, 143).
    """
    from seminspect.core.errors import InvalidInputError
    from seminspect.missions.xflie.config import make_config

    if bag is not None and bag.exists():  # refuse before the mission, not after it
        raise InvalidInputError(f"{bag} exists; choose a new bag name")
    if resume is not None:
        config, out = _resumed(ctx, resume)
    else:
        config = make_config(
            {
                "world": _world_argument(world), "scenario": scenario, "seed": seed,
                "preset": preset, "mode": None if mode is None else mode.value,
                "noise": noise.value, "planner": planner.value, "time_budget_s": budget,
                "map_carving_spacing": carving_spacing,
                "robots": None if robots is None else [r.strip() for r in robots.split(",")],
                "feature_labels": _names(features),
            }
        )  # fmt: skip
        if out is not None:
            writable_directory(out)
    if view:
        from seminspect.missions.xflie.live import refuse_unwatchable

        refuse_unwatchable(config)  # before waiting for a browser
    model = _detector(detector, class_map)
    with _live_view(view_port) if view else contextlib.nullcontext() as server:
        result = _run_with_progress(config, out, query, server, model)
    if pictures and result.stop_signal != signal.SIGTERM:  # SIGTERM asks to stop now
        _draw_pictures(result.run_dir)
    if bag is not None and result.state == "completed":
        _export_bag(result.run_dir, bag)
    _print_result(result)
    if record_mcap and result.stop_signal != signal.SIGTERM:
        _record_mcap(result.run_dir)
    if result.state == "interrupted":
        exit_stopped(result.stop_signal, result.run_dir)


def _names(text: str | None) -> list[str] | None:
    """A comma-separated option as a list (None when not given)."""
    return None if text is None else [name.strip() for name in text.split(",") if name.strip()]


def _world_argument(world: str) -> str:
    """A world path is kept absolute, so the run's config finds it from anywhere."""
    from seminspect.worlds.catalog import is_world_path

    return str(Path(world).resolve()) if is_world_path(world) else world


def _resumed(ctx: typer.Context, run_dir: Path):
    """The configuration and directory of a run to finish; mission settings may not be mixed in."""
    from seminspect.core.errors import InvalidInputError
    from seminspect.missions.xflie.config import make_config
    from seminspect.runs.reuse import resumable_config

    given = [
        f"--{name}"
        for name in (
            "world",
            "scenario",
            "seed",
            "preset",
            "mode",
            "noise",
            "planner",
            "budget",
            "carving_spacing",
            "out",
            "robots",
        )
        if getattr(ctx.get_parameter_source(name), "name", "DEFAULT") != "DEFAULT"
    ]
    if given:
        raise InvalidInputError(
            f"--resume runs the stored configuration of {run_dir}; drop {', '.join(given)}"
        )
    config = make_config(resumable_config(run_dir))
    err_console.print(
        f"resuming {run_dir}: running its configuration again from the start", highlight=False
    )
    return config, run_dir


def _detector(choice: str, class_map: Path | None):
    """None for the simulator's labels, else the user's ONNX model (refused in one line before
    the mission when it or its class map is wrong)."""
    from seminspect.core.errors import InvalidInputError

    if choice == "truth":
        if class_map is not None:
            raise InvalidInputError("--class-map goes with an ONNX --detector, not with truth")
        return None
    if Path(choice).suffix.lower() != ".onnx":
        raise InvalidInputError(
            f"--detector {choice}: expected 'truth' or an ONNX model file (*.onnx)"
        )
    if class_map is None:  # seminspect's own export carries its labels
        from seminspect.perception.learned import LearnedDetector

        return LearnedDetector.load(choice)
    from seminspect.perception.yolo_seg import YoloSegDetector

    return YoloSegDetector.load(choice, class_map)


def _live_view(port: int):
    """The live view's server, once a browser has it open (see :func:`open_live_view`)."""
    from seminspect.report.live_mission import live_page

    return open_live_view(live_page("seminspect mission (live)"), port)


def _run_with_progress(config, out: Path | None, queries: list[str], server=None, detector=None):
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    from seminspect.missions.xflie.live import LiveWatch
    from seminspect.missions.xflie.run import run_mission
    from seminspect.report.live_mission import MissionFeed

    watch = None if server is None else LiveWatch(MissionFeed(server))

    columns = (
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        TextColumn("{task.completed:.0f}/{task.total:.0f} s simulated"),
        TextColumn(
            "{task.fields[phase]}  targets {task.fields[detected]}/{task.fields[inspected]}"
        ),
        TimeElapsedColumn(),
    )
    with Progress(*columns, console=err_console, transient=True) as bar:
        task = bar.add_task("mission", total=1.0, phase="start", detected=0, inspected=0)

        def show(progress) -> None:
            bar.update(
                task,
                total=progress.budget,
                completed=min(progress.sim_time, progress.budget),
                phase=progress.phase,
                detected=progress.detected,
                inspected=progress.inspected,
            )

        return run_mission(
            config, out, queries=queries, progress=show, watch=watch, detector=detector
        )


def _draw_pictures(run_dir: Path) -> None:
    from seminspect.report.html import write_mission_report
    from seminspect.report.run_pictures import render_run

    render_run(run_dir)
    write_mission_report(run_dir)


def _export_bag(run_dir: Path, bag: Path) -> None:
    from rich.progress import MofNCompleteColumn, Progress

    from seminspect.missions.xflie.replay import export_run_bag

    columns = (*Progress.get_default_columns()[:2], MofNCompleteColumn())
    with Progress(*columns, console=err_console, transient=True) as progress:
        task = progress.add_task("replaying LiDAR into the bag", total=None)
        export_run_bag(
            run_dir, bag, on_scan=lambda d, n: progress.update(task, completed=d, total=n)
        )
    console.print(f"ROS2 bag: {bag} (/points PointCloud2 with labels, /odom Odometry)")


def _record_mcap(run_dir: Path) -> None:
    from rich.progress import Progress, TextColumn

    from seminspect.missions.xflie.recording import record_run

    simulated = TextColumn("{task.completed:.0f}/{task.total:.0f} s simulated")
    columns = (*Progress.get_default_columns()[:2], simulated)
    with Progress(*columns, console=err_console, transient=True) as progress:
        task = progress.add_task("recording run.mcap", total=1.0)
        path = record_run(
            run_dir, on_progress=lambda t, end: progress.update(task, completed=t, total=end)
        )
    size_mb = path.stat().st_size / 1e6
    console.print(
        f"MCAP recording: {path} ({size_mb:.1f} MB; Foxglove: File > Open local file)",
        soft_wrap=True,
    )


def _print_result(result) -> None:
    console.print(labelled(f"{result.state}:", "bold", result.reason))
    metrics = result.metrics
    if metrics is None:  # stopped while its outputs were written
        console.print(f"results so far: {result.run_dir}")
        return
    t3, t6, mission = metrics.table3, metrics.table6, metrics.mission
    console.print(
        f"targets detected {t3.detected_pct:.0f}%, inspected {t3.inspected_pct:.0f}% of "
        f"detected; localisation RMSE {_m(t6.localisation_rmse_m)}; "
        f"{mission.sim_time_s:.0f} s simulated in {mission.wall_time_s:.0f} s"
    )
    console.print(
        f"3DLSG: {t3.unified[0]} nodes, {t3.unified[1]} edges (reconciled {t3.reconciled_pct:.1f}%)"
    )
    for answer in result.answers:
        outcome = "reached" if answer.reached else f"not reached ({answer.error or 'too far'})"
        console.print(f"query '{answer.query}': {outcome}")
    # unwrapped: paths are copied from these lines
    outputs = ", ".join(_outputs(result.run_dir))
    console.print(f"results: {result.run_dir}  ({outputs})", soft_wrap=True)
    if (result.run_dir / "graph.json").exists():
        graph = result.run_dir / "graph.json"
        console.print(
            f"query the graph: seminspect graph query {graph} 'Visit ...'", soft_wrap=True
        )


def _outputs(run_dir: Path) -> list[str]:
    """The run's main outputs that exist, so the results line promises nothing absent."""
    return existing_outputs(run_dir, ("report.html", "summary.md", "graph.json"))


def _m(value: float | None) -> str:
    return "-" if value is None else f"{value:.3f} m"
