"""The ``seminspect`` command line.

Each command group lives in its own module and is registered in :data:`GROUPS`. Errors a user
can cause (:class:`~seminspect.core.errors.SeminspectError`) become one line on stderr and exit
code 1; an unexpected exception becomes one line too, with the traceback behind ``--debug``.
Ctrl-C and SIGTERM stop any command with one line saying which (``interrupted by the operator
(Ctrl-C)``, ``stopped by SIGTERM``) and exit code 130 and 143. User text is printed as typed.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import sys
import warnings
from collections.abc import Iterator, Sequence
from typing import Any

import typer
import typer.core
from pydantic import ValidationError

from seminspect import __version__
from seminspect.cli._common import err_console, labelled
from seminspect.core.errors import SeminspectError
from seminspect.core.interrupts import as_interrupted, stop_on_signals
from seminspect.core.validation import describe_validation_error

#: Typer ships its own click; take its usage-error class from a public exception's ancestry.
_USAGE_ERROR: Any = next(c for c in typer.BadParameter.__mro__ if c.__name__ == "UsageError")

#: (module under seminspect.cli, group name, one-line help)
#: Group modules import heavy dependencies inside their commands so ``--help`` stays fast.
GROUPS: tuple[tuple[str, str, str], ...] = (
    ("mission", "mission", "Run an xFLIE inspection mission on a simulated site (paper 000)."),
    ("graph", "graph", "Inspect, query and export 3D Layered Semantic Graphs."),
    ("terrain", "terrain", "Terrain-aware, task-driven outdoor scene graphs (paper 001)."),
    ("routine", "routine", "Routine inspection on an outdated map: adaptive planning (paper 002)."),
    ("world", "world", "List, draw, check and export worlds: the built-in ones and users' sites."),
    ("bench", "bench", "Studies that reproduce the papers' comparisons (planning: 000 Table 5)."),
    ("sweep", "sweep", "Many missions (worlds x scenarios x seeds x settings) on Ray, one table."),
    ("rl", "rl", "Learned semantic inspection in rooms: evaluate and show (paper 004)."),
    (
        "perception",
        "perception",
        "Detectors from pixels: render a labelled dataset, train a segmentation network "
        "(000 Sec III).",
    ),
    ("plan", "plan", "A volumetric path between two points on a map file (.bt, .npz, .ply, .pcd)."),
    ("view", "view", "Open a run's report.html (3D graph, tables, plots) in the browser."),
)


class _CarriedError(Exception):
    """A stop signal or an ``EOFError`` on its way past click to :func:`_report`."""

    def __init__(self, original: KeyboardInterrupt | EOFError) -> None:
        super().__init__(original)
        self.original = original


@contextlib.contextmanager
def _past_click() -> Iterator[None]:
    try:
        yield
    except (KeyboardInterrupt, EOFError) as exc:
        raise _CarriedError(exc) from exc


class _RootGroup(typer.core.TyperGroup):
    """The root command, whose parsing and invocation wrap every command's.

    Typer turns ``KeyboardInterrupt`` into a silent exit 130 (losing which signal it was) and
    ``EOFError`` into ``Abort`` after printing a newline (an unexpected end of a file then reads
    as Ctrl-C); both are carried past it unchanged instead.
    """

    def make_context(self, *args: Any, **kwargs: Any) -> Any:
        with _past_click():
            return super().make_context(*args, **kwargs)

    def invoke(self, ctx: Any) -> Any:
        with _past_click():
            return super().invoke(ctx)


app = typer.Typer(
    cls=_RootGroup,
    name="seminspect",
    help="Semantic-aware autonomous inspection: scene graphs, simulated worlds, missions.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode="rich",
)


def _show_version(value: bool) -> None:
    if value:
        typer.echo(f"seminspect {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(
        False,
        "--version",
        help="Print the version and exit.",
        callback=_show_version,
        is_eager=True,
    ),
    debug: bool = typer.Option(False, "--debug", help="Show full tracebacks on errors."),
) -> None:
    if debug:
        os.environ["SEMINSPECT_DEBUG"] = "1"


def _register_groups() -> None:
    for module_name, group, help_text in GROUPS:
        module = importlib.import_module(f"seminspect.cli.{module_name}")
        if isinstance(module.app, typer.Typer):
            app.add_typer(module.app, name=group, help=help_text)
        else:  # a single command registered as a function
            app.command(name=group, help=help_text)(module.app)


_register_groups()


def main(argv: Sequence[str] | None = None) -> None:
    """Console entry point: run the app and turn errors into one readable line.

    Exit codes: 0 done, 1 a user error, 2 a usage error, 3 a bug, and for a stop signal 128 plus
    its number (130 for Ctrl-C, 143 for SIGTERM, which is handled the same way).
    """
    args = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in args or os.environ.get("SEMINSPECT_DEBUG") == "1"
    with stop_on_signals(), _warnings_as_lines():
        code = _run_app(args, debug)
    raise SystemExit(code)


def _run_app(args: list[str], debug: bool) -> int:
    """The exit code of the app on ``args``, every error reported in one line."""
    try:
        try:
            result = app(args=args, prog_name="seminspect", standalone_mode=False)
        except _CarriedError as carried:
            raise carried.original from None
    except (Exception, KeyboardInterrupt) as exc:
        if debug and not isinstance(exc, typer.Exit | _USAGE_ERROR | KeyboardInterrupt):
            raise
        return _report(exc)
    # typer returns a command's exit code in non-standalone mode instead of exiting
    return result if isinstance(result, int) else 0


def _report(exc: BaseException) -> int:
    """Print what stopped the command in one line; its exit code."""
    if isinstance(exc, typer.Exit):
        code = exc.exit_code
    elif isinstance(exc, _USAGE_ERROR):
        code = 0 if type(exc).__name__ == "NoArgsIsHelpError" else 2  # 0: the help was printed
        if code:
            command = exc.ctx.command_path if exc.ctx else "seminspect"
            _error("error:", f"{exc.format_message()} (see '{command} --help')")
    elif isinstance(exc, KeyboardInterrupt):
        stop = as_interrupted(exc)
        err_console.print(stop.describe(), highlight=False)
        code = stop.exit_code
    elif isinstance(exc, SeminspectError | ValidationError):
        _error(
            "error:",
            describe_validation_error(exc, "value") if isinstance(exc, ValidationError) else exc,
        )
        code = 1
    elif isinstance(exc, OSError) and exc.filename is not None:
        # a file the user named could not be read or written: their fix, not a bug
        _error("error:", f"{exc.filename}: {exc.strerror}")
        code = 1
    else:
        _error(
            "internal error:", f"{type(exc).__name__}: {exc} (rerun with --debug for the traceback)"
        )
        code = 3
    return code


def _error(label: str, message: object) -> None:
    err_console.print(labelled(label, "bold red", message), highlight=False, soft_wrap=True)


@contextlib.contextmanager
def _warnings_as_lines() -> Iterator[None]:
    """Show warnings (a stale lock taken over, ...) as one ``warning:`` line each."""

    def show(message, category, filename, lineno, file=None, line=None) -> None:
        err_console.print(labelled("warning:", "yellow", message), highlight=False, soft_wrap=True)

    previous = warnings.showwarning
    warnings.showwarning = show
    try:
        yield
    finally:
        warnings.showwarning = previous
