"""``seminspect perception``: detectors from pixels, starting with the dataset they learn from."""

from __future__ import annotations

from pathlib import Path

import typer

from seminspect.cli._common import console, exit_stopped, progress_bar, writable_directory

app = typer.Typer(no_args_is_help=True, add_completion=False)

_DATASET_HELP = (
    "Render a labelled dataset of colour frames for a segmentation network.\n\n"
    "Frames look at cars, trucks and buildings (15 % anywhere) from a ground or an aerial "
    "robot's height, each under an appearance of its own. World seeds start at 10000 (20000 "
    "with --held-out, whose appearances training never sees); the evaluation missions use 0-59. "
    "An interrupted run, rerun with the same arguments, finishes the dataset with the same bytes."
)


def _size(text: str) -> tuple[int, int]:
    """``WxH`` as ``(width, height)``."""
    from seminspect.core.errors import InvalidInputError

    width, sep, height = text.lower().partition("x")
    if not (sep and width.isdigit() and height.isdigit()):
        raise InvalidInputError(f"--size takes WIDTHxHEIGHT in pixels (e.g. 320x240), got {text!r}")
    return int(width), int(height)


@app.command(help=_DATASET_HELP)
def dataset(
    out: Path = typer.Option(..., "--out", "-o", help="Directory to write (or to finish)."),
    frames: int = typer.Option(2000, "--frames", help="Frames to render."),
    worlds: str = typer.Option(
        "city:small,city:medium,campus:small",
        "--worlds",
        help="Worlds as name[:scenario], separated by commas; frames take them in turn.",
    ),
    size: str = typer.Option("320x240", "--size", help="Image size WIDTHxHEIGHT in pixels."),
    held_out: bool = typer.Option(
        False, "--held-out", help="Held-out worlds (seeds 20000 up) and appearances."
    ),
    seed: int = typer.Option(0, "--seed", help="Seed of every view, appearance and noise draw."),
    shard_size: int = typer.Option(64, "--shard-size", help="Frames per shard file."),
) -> None:
    from seminspect.core.interrupts import as_interrupted
    from seminspect.perception.dataset import (
        DatasetSpec,
        build_dataset,
        dataset_statistics,
        parse_worlds,
    )

    width, height = _size(size)
    spec = DatasetSpec(parse_worlds(worlds), frames, width, height, held_out, seed, shard_size)
    writable_directory(out)
    bar = progress_bar()
    task = bar.add_task(f"{spec.split} frames", total=spec.frames)

    def show(done: int, total: int) -> None:
        if not bar.live.is_started:  # at the first report: an error before it prints alone
            bar.start()
        bar.update(task, completed=done, total=total)

    try:
        try:
            built = build_dataset(out, spec, on_progress=show)
        finally:
            if bar.live.is_started:
                bar.stop()
    except KeyboardInterrupt as exc:
        exit_stopped(as_interrupted(exc).signum, out)
    console.print(f"dataset: {built.path} ({built.shards} shards)", soft_wrap=True)
    console.print(dataset_statistics(built).summary(), soft_wrap=True)


@app.command()
def train(
    dataset_dir: Path = typer.Argument(..., help="A dataset that 'perception dataset' wrote."),
    out: Path = typer.Option(..., "--out", "-o", help="Run directory (checkpoint, logs)."),
    steps: int = typer.Option(2000, "--steps", help="Optimiser steps.", min=1),
    batch: int = typer.Option(16, "--batch", help="Frames per step.", min=1),
    lr: float = typer.Option(2e-3, "--lr", help="Peak learning rate (AdamW, cosine decay)."),
    seed: int = typer.Option(0, "--seed", help="Seed of the weights, batches and augmentation."),
    threads: int = typer.Option(2, "--threads", help="Torch threads.", min=1),
    max_minutes: float | None = typer.Option(
        None, "--max-minutes", help="Stop (state saved) at the first step after this long.", min=0
    ),
    resume: bool = typer.Option(
        False, "--resume", help="Continue the run in --out from its saved state, bit for bit."
    ),
) -> None:
    """Train the segmentation network (classes, parts, seams) on a rendered dataset.

    Writes checkpoint.pt, training-state.pt and progress.csv into --out; --max-minutes,
    Ctrl-C and SIGTERM save the state and --resume continues it with the same settings.
    """
    from seminspect.perception.training import train_detector

    if not resume:
        writable_directory(out)
    with console.status(f"training on {dataset_dir} (progress.csv in {out})"):
        result = train_detector(
            dataset_dir, out, steps=steps, batch=batch, lr=lr, seed=seed, threads=threads,
            max_minutes=max_minutes, resume=resume,
        )  # fmt: skip
    last = result.rows[-1] if result.rows else {}
    state = "finished" if result.finished else "stopped (--resume continues it)"
    figures = ", ".join(f"{k} {v:.3f}" for k, v in last.items() if k != "step")
    console.print(
        f"{result.steps} of {steps} steps {state} in {result.wall_s / 60:.1f} min; "
        f"{result.parameters:,} parameters; {figures}",
        soft_wrap=True,
    )
    console.print(f"checkpoint: {result.checkpoint}", soft_wrap=True)


@app.command()
def export(
    checkpoint: Path = typer.Argument(..., help="checkpoint.pt of 'perception train'."),
    out: Path = typer.Option(..., "--out", "-o", help="The ONNX model to write (*.onnx)."),
) -> None:
    """Export a trained network to ONNX, its labels in the model's metadata, for
    'seminspect mission --detector MODEL.onnx' and CPU inference without torch."""
    from seminspect.core.errors import InvalidInputError
    from seminspect.perception.segnet_io import export_onnx

    if out.suffix.lower() != ".onnx":
        raise InvalidInputError(f"--out {out}: an ONNX model is named *.onnx")
    path = export_onnx(checkpoint, out)
    console.print(f"wrote {path} ({path.stat().st_size / 1e6:.2f} MB)", soft_wrap=True)
