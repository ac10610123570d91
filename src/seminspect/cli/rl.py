"""``seminspect rl``: the learned inspection policy of 004 and its baselines in random rooms."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import typer

from seminspect.cli._common import (
    console,
    existing_outputs,
    open_live_view,
    progress_bar,
    view_options,
)

if TYPE_CHECKING:
    from seminspect.missions.learning.env_config import EnvConfig, TargetShape
    from seminspect.missions.learning.live import LiveWatch

app = typer.Typer(no_args_is_help=True, help="Learned semantic inspection in rooms (004).")

#: Controllers known by name; anything else is a checkpoint file.
BASELINES = ("random", "orbit")

_POLICY = typer.Option(
    None,
    "--policy",
    "-p",
    help="random, orbit, or a policy checkpoint file; default: the shipped policy.",
)
_SEED = typer.Option(0, "--seed", help="Seed of the rooms, noise and random policy.", min=0)
_ENVS = typer.Option(64, "--envs", help="Rooms stepped together.", min=1, max=512)
_THREADS = typer.Option(1, "--threads", help="Ray-casting threads.", min=1, max=64)
_VIEW, _VIEW_PORT = view_options("the episode", ", then flies it in real time")


def parse_obstacles(text: str) -> list[int]:
    """``"0,4,9"`` -> ``[0, 4, 9]``: distinct non-negative counts within the rooms' limit."""
    from seminspect.core.errors import InvalidInputError
    from seminspect.missions.learning.env import EnvConfig

    limit = EnvConfig.model_fields["obstacles"].metadata
    most = next(m.le for m in limit if hasattr(m, "le"))
    try:
        counts = [int(part) for part in text.split(",")]
    except ValueError:
        raise InvalidInputError(
            f"--obstacles must be comma-separated whole numbers like 0,4,9, got {text!r}"
        ) from None
    if any(not 0 <= k <= most for k in counts):
        raise InvalidInputError(f"--obstacles must lie in 0-{most}, got {text!r}")
    if len(set(counts)) != len(counts):
        raise InvalidInputError(f"--obstacles repeats a count: {text!r}")
    return counts


def controller_for(policy: str | None, seed: int):
    """The baseline named ``policy``, or the learned policy from a checkpoint (None: shipped)."""
    from seminspect.core.errors import InvalidInputError
    from seminspect.missions.learning.baselines import OrbitController, RandomController

    if policy == "random":
        return RandomController(seed)
    if policy == "orbit":
        return OrbitController()
    if policy is not None and not Path(policy).is_file():
        raise InvalidInputError(
            f"unknown policy {policy!r}: use {', '.join(BASELINES)} or a checkpoint file"
        )
    _require_torch()
    from seminspect.missions.learning.agent import load_controller

    return load_controller(None if policy is None else Path(policy))


def _require_torch() -> None:
    """The learned policy runs on torch, an optional extra: say how to get it."""
    from seminspect.core.errors import InvalidInputError

    try:
        import torch  # noqa: F401 - only checking that it is there
    except ImportError:
        raise InvalidInputError(
            "the learned policy needs torch, which is not installed: pip install 'seminspect[rl]'"
        ) from None


def _policy_name(policy: str | None) -> str:
    return "shipped" if policy is None else Path(policy).name


@app.command("eval")
def eval_command(
    policy: str | None = _POLICY,
    obstacles: str = typer.Option(
        "0,4,9,14,19", "--obstacles", help="Comma-separated obstacle counts (004 Table I)."
    ),
    episodes: int = typer.Option(20, "--episodes", "-n", help="Episodes per obstacle count."),
    seed: int = _SEED,
    envs: int = _ENVS,
    threads: int = _THREADS,
    shapes: str = typer.Option(
        "cylinder", "--shapes", help="Comma-separated object shapes: cylinder, box, sphere, t-pipe."
    ),
    out: Path = typer.Option(
        ..., "--out", "-o", help="Directory for evaluation.json, report.html and PNGs."
    ),
) -> None:
    """Coverage (lenient and strict), crash % and timeout % per obstacle count, beside 004
    Table I; the policy flies with the observations of the environment it was trained in."""
    from seminspect.cli._common import writable_directory
    from seminspect.core.errors import InvalidInputError
    from seminspect.core.io import file_sha256
    from seminspect.missions.learning.evaluation import (
        EpisodeTrace,
        controller_evaluation_config,
        evaluate,
    )
    from seminspect.report.figures import save_figure
    from seminspect.report.html import write_rl_report
    from seminspect.report.rl import coverage_figure, write_episode_pictures

    counts = parse_obstacles(obstacles)
    objects = _parse_shapes(shapes)
    if episodes < 1:
        raise InvalidInputError(f"--episodes must be at least 1, got {episodes}")
    writable_directory(out)
    controller = controller_for(policy, seed)
    config = controller_evaluation_config(controller, objects)
    checkpoint = _checkpoint_file(policy)
    name = _policy_name(policy)
    traces: dict[int, EpisodeTrace] = {}
    with progress_bar() as bar:
        task = bar.add_task(f"{name}", total=1.0)

        def show(label: str, share: float) -> None:
            bar.update(task, completed=share, description=f"{name}: {label}")

        result = evaluate(
            controller,
            counts,
            episodes,
            seed,
            config=config,
            num_envs=envs,
            progress=show,
            policy=name,
            threads=threads,
            traces=traces,
            checkpoint_sha256=None if checkpoint is None else file_sha256(checkpoint),
        )
    result.to_json(out / "evaluation.json")
    save_figure(coverage_figure({name: result}), out / "coverage.png")
    for count, trace in traces.items():
        write_episode_pictures(
            trace,
            result.config.model_copy(update={"obstacles": count}),
            out,
            prefix=f"episode_{count:02d}",
            title=f"{name}, {count} obstacles",
        )
    write_rl_report(out)
    _print_table(result)
    # unwrapped: paths are copied from this line
    outputs = ", ".join(existing_outputs(out, ("report.html", "evaluation.json")))
    console.print(f"{result.wall_seconds:.1f} s; results: {out}  ({outputs})", soft_wrap=True)


def _parse_shapes(text: str) -> tuple[TargetShape, ...]:
    """``"cylinder,box"`` -> ``("cylinder", "box")``: known, distinct object shapes."""
    from seminspect.core.errors import InvalidInputError
    from seminspect.missions.learning.env_config import TARGET_SHAPES

    names = [part.strip() for part in text.split(",")]
    if unknown := [s for s in names if s not in TARGET_SHAPES]:
        raise InvalidInputError(
            f"--shapes: unknown shape {unknown[0]!r}; use some of {', '.join(TARGET_SHAPES)}"
        )
    if len(set(names)) != len(names):
        raise InvalidInputError(f"--shapes repeats a shape: {text!r}")
    return tuple(shape for name in names for shape in TARGET_SHAPES if shape == name)


def _checkpoint_file(policy: str | None) -> Path | None:
    """The checkpoint file a policy flies (the shipped one for None); None for a baseline."""
    if policy in BASELINES:
        return None
    from seminspect.missions.learning.agent import shipped_policy_path

    return shipped_policy_path() if policy is None else Path(policy)


def _print_table(result) -> None:
    """Ours beside 004 Table I; timeouts are left out (100 % - crashes) to fit 80 columns."""
    from rich.table import Table

    from seminspect.missions.learning.evaluation import PAPER_TABLE1, interval_text

    shapes = ", ".join(result.config.target_shapes)
    title = f"{result.policy} ({shapes}): {result.results[0].episodes} episodes per row"
    caption = "strict: % of the feasible faces; [ ]: 95 % interval; timeout % = 100 - crash %"
    table = Table(title=title, caption=caption)
    for header in ("obstacles", "coverage %", "strict %", "004", "crash %", "004"):
        table.add_column(header, justify="right")
    for row in result.results:
        paper = PAPER_TABLE1.get(row.obstacles)
        table.add_row(
            str(row.obstacles),
            f"{row.coverage_pct:.1f}",
            interval_text(row.strict_coverage_pct, row.strict_coverage_ci),
            "-" if paper is None else f"{paper[0]:.1f}",
            interval_text(row.crash_pct, row.crash_ci),
            "-" if paper is None else f"{paper[1]:.1f}",
        )
    console.print(table)
    for row in result.results:
        if struck := row.crashes_into():
            named = ", ".join(f"{surface} {count}" for surface, count in struck.items())
            console.print(f"crashes at {row.obstacles} obstacles struck: {named}")


@app.command("show")
def show_command(
    policy: str | None = _POLICY,
    obstacles: int = typer.Option(9, "--obstacles", help="Obstacles in the room.", min=0, max=60),
    seed: int = _SEED,
    out: Path = typer.Option(..., "--out", "-o", help="Directory for the episode's PNGs."),
    view: bool = _VIEW,
    view_port: int = _VIEW_PORT,
) -> None:
    """Fly one recorded episode in the rooms the policy was trained in and draw it (top-down,
    3D, coverage against time)."""
    from seminspect.cli._common import writable_directory
    from seminspect.missions.learning.live import CRASHED, play_episode
    from seminspect.report.rl import write_episode_pictures

    writable_directory(out)
    controller = controller_for(policy, seed)
    config = env_config_for(controller).model_copy(update={"obstacles": obstacles})
    with _watched(view, view_port) as watch, progress_bar() as bar:
        task = bar.add_task("episode", total=config.steps_per_episode)
        flown = play_episode(
            controller, config, seed, watch=watch,
            progress=lambda step: bar.update(task, completed=step),
        )  # fmt: skip
    name = _policy_name(policy)
    title = f"{name}, {obstacles} obstacles"
    written = write_episode_pictures(flown.trace, config, out, title=title)
    ending = "crashed" if flown.ending == CRASHED else "timeout (no crash)"
    console.print(f"coverage {100.0 * flown.coverage:.1f} %, {ending}")
    console.print(f"pictures: {', '.join(str(p) for p in written)}")


@contextmanager
def _watched(view: bool, port: int) -> Iterator[LiveWatch | None]:
    """The live view's watch for ``--view`` (None without it); its server closes after the
    episode."""
    if not view:
        yield None
        return
    from seminspect.missions.learning.live import LiveWatch
    from seminspect.report.live_rl import EpisodeFeed, episode_page

    with open_live_view(episode_page("seminspect rl show (live)"), port) as server:
        yield LiveWatch(EpisodeFeed(server), real_time=True)


def env_config_for(controller: object) -> EnvConfig:
    """The environment a controller was trained in (a checkpoint's ``env_config``); a
    baseline, trained in none, gets the defaults."""
    from seminspect.missions.learning.env_config import EnvConfig

    config = getattr(controller, "env_config", None)
    return config if isinstance(config, EnvConfig) else EnvConfig()


#: Options that set up a new run: with --resume the saved run's own settings hold.
_NEW_RUN_OPTIONS = ("config", "variant", "steps", "seed", "envs", "device", "out", "init_from")


@app.command("train")
def train_command(
    ctx: typer.Context,
    config: str = typer.Option(
        "small", "--config", help="Network: small (sized for a CPU) or paper (004 Fig 2)."
    ),
    variant: str = typer.Option(
        "main", "--variant", help="main, no-svs (Table II), no-gru or gru-512 (Table III)."
    ),
    steps: int = typer.Option(640_000, "--steps", help="Environment steps, all rooms together."),
    seed: int = _SEED,
    envs: int = typer.Option(64, "--envs", help="Rooms stepped together.", min=1, max=512),
    device: str = typer.Option("cpu", "--device", help="Torch device for the network (cpu, cuda)."),
    out: Path | None = typer.Option(
        None, "--out", "-o", help="Directory for checkpoint.pt, training-state.pt and the logs."
    ),
    resume: Path | None = typer.Option(
        None,
        "--resume",
        help="Continue the run in this directory from its last saved state, with its settings.",
    ),
    init_from: Path | None = typer.Option(
        None,
        "--init-from",
        help="Fine-tune: start from this checkpoint's weights and network (9 obstacles "
        "from the first step; the run records the checkpoint's SHA-256).",
    ),
    max_minutes: float | None = typer.Option(
        None,
        "--max-minutes",
        min=0.0,
        help="Stop at the first update boundary after this many minutes, state saved.",
    ),
) -> None:
    """Train a policy with recurrent PPO and the obstacle curriculum, in pieces if need be:
    --max-minutes, Ctrl-C or SIGTERM save the state, --resume continues it."""
    from seminspect.core.errors import InvalidInputError

    _require_torch()
    stop_after_s = None if max_minutes is None else 60.0 * max_minutes
    if resume is not None:
        given = [name for name in _NEW_RUN_OPTIONS if _given(ctx, name)]
        if given:
            options = ", ".join(f"--{name}" for name in given)
            raise InvalidInputError(
                f"--resume continues a run with its own settings; drop {options}"
            )
        _resume_run(resume, stop_after_s)
        return
    if init_from is not None and (_given(ctx, "config") or _given(ctx, "variant")):
        raise InvalidInputError(
            "--init-from takes the checkpoint's network; drop --config and --variant"
        )
    if out is None:
        raise InvalidInputError("--out is needed for a new run (or --resume DIR to continue one)")
    if steps < 1:
        raise InvalidInputError(f"--steps must be at least 1, got {steps}")
    _new_run(config, variant, steps, seed, envs, device, out, stop_after_s, init_from)


def _given(ctx: typer.Context, name: str) -> bool:
    # by name: typer's own click has its own ParameterSource enum
    source = ctx.get_parameter_source(name)
    return source is not None and source.name not in ("DEFAULT", "DEFAULT_MAP")


def _new_run(
    config: str,
    variant: str,
    steps: int,
    seed: int,
    envs: int,
    device: str,
    out: Path,
    stop_after_s: float | None,
    init_from: Path | None,
) -> None:
    from seminspect.cli._common import writable_directory
    from seminspect.core.io import file_sha256
    from seminspect.missions.learning.checkpoints import read_checkpoint
    from seminspect.missions.learning.env import InspectionVectorEnv
    from seminspect.missions.learning.ppo import train
    from seminspect.missions.learning.recipes import (
        policy_config,
        train_config,
        training_env_config,
    )

    _check_device(device)
    initial = None if init_from is None else read_checkpoint(init_from).policy
    network = initial.config if initial is not None else policy_config(config, variant)  # type: ignore[arg-type]
    parent = None if init_from is None else file_sha256(init_from)
    settings = train_config(steps, seed=seed, num_envs=envs, init_from=parent)
    rooms = training_env_config(network)
    writable_directory(out)

    def make_env(count: int, env_seed: int) -> InspectionVectorEnv:
        return InspectionVectorEnv(count, rooms, seed=env_seed)

    def run(progress):
        return train(
            make_env,
            network,
            settings,
            out,
            env_config=rooms,
            progress=progress,
            device=device,
            stop_after_s=stop_after_s,
            initial=initial,
        )

    label = f"{config}/{variant}" if init_from is None else f"fine-tune of {init_from}"
    _train_with_bar(label, settings.total_steps, out, run)


def _resume_run(run_dir: Path, stop_after_s: float | None) -> None:
    from seminspect.missions.learning.ppo import resume
    from seminspect.missions.learning.training_state import (
        TRAINING_STATE_NAME,
        read_training_state,
    )

    state = read_training_state(run_dir / TRAINING_STATE_NAME)
    total = state.train_config.total_steps
    if state.finished:
        console.print(
            f"{run_dir}: the run is finished ({state.steps:,} of {total:,} steps); "
            "nothing to resume",
            soft_wrap=True,
        )
        return
    _check_device(state.device)

    def run(progress):
        return resume(state, run_dir, progress=progress, stop_after_s=stop_after_s)

    _train_with_bar(f"{run_dir.name}, from step {state.steps:,}", total, run_dir, run)


def _train_with_bar(label: str, total: int, run_dir: Path, run) -> None:
    """``run(progress)`` under a progress bar, then the line that says how it ended."""
    from seminspect.cli._common import err_console
    from seminspect.core.interrupts import as_interrupted
    from seminspect.missions.learning.ppo import ProgressRow
    from seminspect.missions.learning.training_state import TRAINING_STATE_NAME

    again = f"continue with: seminspect rl train --resume {run_dir}"
    with progress_bar() as bar:
        task = bar.add_task(label, total=total)

        def show(row: ProgressRow) -> None:
            coverage = "" if row.episodes == 0 else f", coverage {row.coverage_pct:.0f} %"
            text = f"{label}: {row.steps_per_s:.0f} steps/s{coverage}"
            bar.update(task, completed=min(row.steps, total), description=text)

        try:
            result = run(show)
        except KeyboardInterrupt as exc:
            if not (run_dir / TRAINING_STATE_NAME).is_file():
                raise
            stop = as_interrupted(exc)
            err_console.print(f"{stop.describe()}; {again}", highlight=False, soft_wrap=True)
            raise typer.Exit(stop.exit_code) from None
    minutes = result.wall_s / 60
    if not result.finished:  # unwrapped: the command is copied from this line
        console.print(
            f"stopped at step {result.steps:,} of {total:,} after {minutes:.1f} min; {again}",
            soft_wrap=True,
        )
        return
    console.print(
        f"{result.steps:,} steps in {minutes:.1f} min; "
        f"checkpoint: {result.checkpoint} (progress.csv beside it)",
        soft_wrap=True,
    )


def _check_device(name: str) -> None:
    """A torch device that exists here: ``cpu``, or ``cuda`` when a GPU is visible."""
    import torch

    from seminspect.core.errors import InvalidInputError

    try:
        kind = torch.device(name).type
    except RuntimeError:
        raise InvalidInputError(f"--device {name!r} is not a torch device (cpu, cuda)") from None
    if kind == "cuda" and not torch.cuda.is_available():
        raise InvalidInputError("--device cuda: no CUDA device is visible on this machine")
    if kind not in ("cpu", "cuda"):
        raise InvalidInputError(f"--device {name!r}: only cpu and cuda are supported")
