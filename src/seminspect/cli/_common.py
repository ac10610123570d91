"""Consoles shared by the command groups, the checks every command makes of its outputs, and
how a command that saved its partial results after a stop signal ends.

The consoles do not interpret rich markup: what a user typed (a query, a path, a node name)
is printed as typed, ``[/b]`` included. Styled words are built with :class:`rich.text.Text`.
"""

from __future__ import annotations

import os
import signal
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn

import typer
from rich.console import Console
from rich.text import Text

from seminspect.core.errors import InvalidInputError
from seminspect.core.interrupts import Interrupted

console = Console(markup=False)
err_console = Console(stderr=True, markup=False)


def labelled(label: str, style: str, message: object) -> Text:
    """``label`` in ``style`` followed by ``message`` printed literally."""
    return Text.assemble((label, style), " ", str(message))


def progress_bar():
    """A transient rich progress bar on stderr: description, bar, elapsed time."""
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    return Progress(
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        TimeElapsedColumn(),
        console=err_console,
        transient=True,
    )


def exit_stopped(signum: int | None, partial: Path) -> NoReturn:
    """End a command whose work a stop signal cut short once its partial results are saved:
    the line and the exit code (128 plus the signal) every stopped command ends with."""
    stop = Interrupted(signum or signal.SIGINT)
    message = f"{stop.describe()}; partial results in {partial}"
    err_console.print(message, highlight=False, soft_wrap=True)
    raise typer.Exit(stop.exit_code)


def writable_file(path: Path, suffixes: tuple[str, ...] = ()) -> Path:
    """Check, before any work, that ``path`` can be written as a file (of one of ``suffixes``)."""
    if path.is_dir():
        raise InvalidInputError(f"{path} is a directory; give a file name to write")
    if suffixes and path.suffix.lower() not in suffixes:
        raise InvalidInputError(
            f"{path}: cannot write {path.suffix or 'a file without suffix'}; "
            f"use one of {', '.join(suffixes)}"
        )
    _check_parent(path)
    return path


def writable_directory(path: Path) -> Path:
    """Check, before any work, that ``path`` is or can become a writable directory."""
    if path.exists() and not path.is_dir():
        raise InvalidInputError(f"{path} exists and is not a directory; choose another --out")
    if path.is_dir():
        if not os.access(path, os.W_OK | os.X_OK):
            raise InvalidInputError(f"{path} is not writable; choose another --out")
        return path
    _check_parent(path)
    return path


def _check_parent(path: Path) -> None:
    """The nearest existing folder above ``path`` must be a writable directory."""
    parent = path.absolute().parent
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise InvalidInputError(f"{path}: {parent} is not a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InvalidInputError(f"{path}: {parent} is not writable; choose another location")


def existing_outputs(run_dir: Path, names: Sequence[str]) -> list[str]:
    """Those of ``names`` that exist in the run directory, then how many pictures it holds, so
    a results line promises nothing absent."""
    named = [name for name in names if (run_dir / name).exists()]
    pictures = len(list(run_dir.glob("*.png")))
    return named + ([f"{pictures} pictures (*.png)"] if pictures else ["no pictures"])


#: The longest a command with ``--view`` waits for a browser before it starts the run anyway.
VIEW_WAIT_S = 60.0


def view_options(what: str, note: str = "") -> tuple[bool, int]:
    """The ``--view`` and ``--view-port`` options of a command whose run can be watched live
    (``note``: what else the help should say)."""
    view = typer.Option(
        False,
        "--view",
        help=f"Watch {what} live in a browser: a page on localhost (its address is printed); "
        f"the run waits up to {VIEW_WAIT_S:.0f} s for the page to be opened{note}.",
    )
    port = typer.Option(
        8765, "--view-port", help="Port of --view on localhost (0: any free one).", min=0,
        max=65535,
    )  # fmt: skip
    return view, port


def open_live_view(page: str, port: int):
    """A live view's server for ``page``, once a browser has opened it (or after
    :data:`VIEW_WAIT_S`): a short run would otherwise be over before anyone could look. A
    port in use is one clear line."""
    from seminspect.report.live_server import LiveServer

    server = LiveServer(page, port)
    err_console.print(
        f"live view at {server.url}: open it in a browser (the run starts when it is open, or "
        f"in {VIEW_WAIT_S:.0f} s)",
        highlight=False,
        soft_wrap=True,
    )
    try:
        server.wait_for_client(VIEW_WAIT_S)
    except BaseException:
        server.close()
        raise
    return server
