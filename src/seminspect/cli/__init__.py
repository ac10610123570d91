"""The ``seminspect`` command line.

Each command group lives in its own module and is registered in :data:`GROUPS`. Errors a user
can cause (:class:`~seminspect.core.errors.SeminspectError`) become one line on stderr and exit
code 1; an unexpected exception becomes one line too, with the traceback behind ``--debug``.
"""

from __future__ import annotations

import importlib
import os
import sys
from collections.abc import Sequence
from typing import Any

import typer
from pydantic import ValidationError

from seminspect import __version__
from seminspect.cli._common import err_console
from seminspect.core.errors import SeminspectError
from seminspect.core.validation import describe_validation_error

#: Typer ships its own click; take its usage-error class from a public exception's ancestry.
_USAGE_ERROR: Any = next(c for c in typer.BadParameter.__mro__ if c.__name__ == "UsageError")

#: (module under seminspect.cli, group name, one-line help)
#: Group modules import heavy dependencies inside their commands so ``--help`` stays fast.
GROUPS: tuple[tuple[str, str, str], ...] = (
    ("mission", "mission", "Run an xFLIE inspection mission on a simulated site (paper 000)."),
    ("graph", "graph", "Inspect, query and export 3D Layered Semantic Graphs."),
    ("terrain", "terrain", "Terrain-aware, task-driven outdoor scene graphs (paper 001)."),
    ("world", "world", "List, draw and export the built-in simulated worlds."),
    ("bench", "bench", "Studies that reproduce the papers' comparisons (planning: 000 Table 5)."),
)

app = typer.Typer(
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
    """Console entry point: run the app and turn errors into one readable line."""
    args = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in args or os.environ.get("SEMINSPECT_DEBUG") == "1"
    try:
        app(args=args, prog_name="seminspect", standalone_mode=False)
    except typer.Exit as done:
        raise SystemExit(done.exit_code) from None
    except _USAGE_ERROR as exc:
        if type(exc).__name__ == "NoArgsIsHelpError":  # the help was printed
            raise SystemExit(0) from None
        command = exc.ctx.command_path if exc.ctx else "seminspect"
        err_console.print(
            f"[bold red]error:[/] {exc.format_message()} (see '{command} --help')",
            highlight=False,
            soft_wrap=True,
        )
        raise SystemExit(2) from None
    except typer.Abort:
        err_console.print("interrupted", highlight=False)
        raise SystemExit(130) from None
    except (SeminspectError, ValidationError) as exc:
        if debug:
            raise
        message = (
            describe_validation_error(exc, "value") if isinstance(exc, ValidationError) else exc
        )
        err_console.print(f"[bold red]error:[/] {message}", highlight=False, soft_wrap=True)
        raise SystemExit(1) from None
    except KeyboardInterrupt:
        err_console.print("interrupted", highlight=False)
        raise SystemExit(130) from None
    except Exception as exc:
        if debug:
            raise
        err_console.print(
            f"[bold red]internal error:[/] {type(exc).__name__}: {exc} "
            "(rerun with --debug for the traceback)",
            highlight=False,
            soft_wrap=True,
        )
        raise SystemExit(3) from None
