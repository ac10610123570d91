"""``seminspect rl``: the learned inspection policy of 004 and its baselines in random rooms."""

from __future__ import annotations

from pathlib import Path

import typer

from seminspect.cli._common import console, existing_outputs, progress_bar

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
    out: Path = typer.Option(
        ..., "--out", "-o", help="Directory for evaluation.json, report.html and PNGs."
    ),
) -> None:
    """Coverage, crash % and timeout % per obstacle count, beside 004 Table I."""
    from seminspect.cli._common import writable_directory
    from seminspect.core.errors import InvalidInputError
    from seminspect.missions.learning.evaluation import EpisodeTrace, evaluate
    from seminspect.report.figures import save_figure
    from seminspect.report.html import write_rl_report
    from seminspect.report.rl import coverage_figure, write_episode_pictures

    counts = parse_obstacles(obstacles)
    if episodes < 1:
        raise InvalidInputError(f"--episodes must be at least 1, got {episodes}")
    writable_directory(out)
    controller = controller_for(policy, seed)
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
            num_envs=envs,
            progress=show,
            policy=name,
            threads=threads,
            traces=traces,
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


def _print_table(result) -> None:
    from rich.table import Table

    from seminspect.missions.learning.evaluation import PAPER_TABLE1

    table = Table(title=f"{result.policy}: {result.results[0].episodes} episodes per row")
    for header in ("obstacles", "coverage %", "004", "crash %", "004", "timeout %", "004"):
        table.add_column(header, justify="right")
    for row in result.results:
        paper = PAPER_TABLE1.get(row.obstacles)
        ours = (row.coverage_pct, row.crash_pct, row.timeout_pct)
        cells = [str(row.obstacles)]
        for k, value in enumerate(ours):
            cells += [f"{value:.1f}", "-" if paper is None else f"{paper[k]:.1f}"]
        table.add_row(*cells)
    console.print(table)


@app.command("show")
def show_command(
    policy: str | None = _POLICY,
    obstacles: int = typer.Option(9, "--obstacles", help="Obstacles in the room.", min=0, max=60),
    seed: int = _SEED,
    out: Path = typer.Option(..., "--out", "-o", help="Directory for the episode's PNGs."),
) -> None:
    """Fly one recorded episode and draw it (top-down, 3D, coverage against time)."""
    from seminspect.cli._common import writable_directory
    from seminspect.missions.learning.env import EnvConfig, InspectionVectorEnv
    from seminspect.missions.learning.evaluation import EpisodeTrace
    from seminspect.report.rl import write_episode_pictures

    writable_directory(out)
    controller = controller_for(policy, seed)
    config = EnvConfig(obstacles=obstacles)
    env = InspectionVectorEnv(1, config, seed=seed, autoreset=False, record=True)
    obs, _ = env.reset(seed=seed)
    controller.reset(env)
    crashed = False
    with progress_bar() as bar:
        task = bar.add_task("episode", total=config.steps_per_episode)
        for _ in range(config.steps_per_episode):
            obs, _, crash, _, _ = env.step(controller.act(env, obs))
            crashed = bool(crash[0])
            if crashed:
                break
            bar.advance(task)
    trace = EpisodeTrace(env.rooms[0], env.track(0), env.face_distances(0), crashed)
    name = _policy_name(policy)
    written = write_episode_pictures(trace, config, out, title=f"{name}, {obstacles} obstacles")
    ending = "crashed" if crashed else "timeout (no crash)"
    console.print(f"coverage {100.0 * env.coverage()[0]:.1f} %, {ending}")
    console.print(f"pictures: {', '.join(str(p) for p in written)}")


@app.command("train")
def train_command(
    config: str = typer.Option(
        "small", "--config", help="Network: small (sized for a CPU) or paper (004 Fig 2)."
    ),
    variant: str = typer.Option(
        "main", "--variant", help="main, no-svs (Table II) or no-gru (Table III)."
    ),
    steps: int = typer.Option(640_000, "--steps", help="Environment steps, all rooms together."),
    seed: int = _SEED,
    envs: int = typer.Option(64, "--envs", help="Rooms stepped together.", min=1, max=512),
    device: str = typer.Option("cpu", "--device", help="Torch device for the network (cpu, cuda)."),
    out: Path = typer.Option(..., "--out", "-o", help="Directory for checkpoint.pt and logs."),
) -> None:
    """Train a policy with recurrent PPO and the obstacle curriculum; Ctrl-C keeps a checkpoint."""
    from seminspect.cli._common import writable_directory
    from seminspect.core.errors import InvalidInputError
    from seminspect.missions.learning.env import InspectionVectorEnv
    from seminspect.missions.learning.ppo import ProgressRow, train
    from seminspect.missions.learning.recipes import (
        policy_config,
        train_config,
        training_env_config,
    )

    if steps < 1:
        raise InvalidInputError(f"--steps must be at least 1, got {steps}")
    _require_torch()
    _check_device(device)
    network = policy_config(config, variant)  # type: ignore[arg-type]
    settings = train_config(steps, seed=seed, num_envs=envs)
    rooms = training_env_config(network)
    writable_directory(out)

    def make_env(count: int, env_seed: int) -> InspectionVectorEnv:
        return InspectionVectorEnv(count, rooms, seed=env_seed)

    with progress_bar() as bar:
        task = bar.add_task(f"{config}/{variant}", total=steps)

        def show(row: ProgressRow) -> None:
            coverage = "" if row.episodes == 0 else f", coverage {row.coverage_pct:.0f} %"
            label = f"{config}/{variant}: {row.steps_per_s:.0f} steps/s{coverage}"
            bar.update(task, completed=min(row.steps, steps), description=label)

        result = train(make_env, network, settings, out, progress=show, device=device)
    console.print(
        f"{result.steps:,} steps in {result.wall_s / 60:.1f} min; "
        f"checkpoint: {result.checkpoint} (progress.csv beside it)"
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
