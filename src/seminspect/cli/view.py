"""``seminspect view``: open a run's report in the browser, served from localhost.

viser (spark-dsg's live viewer; 1.1.1 when this was written) needs rich < 15, which conflicts
with the rich 15 seminspect's environment carries, so the viewer is the run's ``report.html``
(plotly, turnable and queryable in 3D) served by the standard library's HTTP server on
127.0.0.1 only.
"""

from __future__ import annotations

import functools
import http.server
from pathlib import Path

import typer

from seminspect.cli._common import console


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: object) -> None:
        """Requests are not worth a line each on the console."""


def make_server(root: Path, port: int) -> http.server.ThreadingHTTPServer:
    """A server of ``root`` on 127.0.0.1 (``port`` 0 picks a free one)."""
    handler = functools.partial(_QuietHandler, directory=str(root))
    return http.server.ThreadingHTTPServer(("127.0.0.1", port), handler)


def app(
    run_dir: Path = typer.Argument(
        ...,
        help="A run directory: mission, terrain graph, routine inspection (run, routine map or "
        "--compare directory) or rl eval.",
    ),
    port: int = typer.Option(8765, "--port", help="Port on localhost (0: any free one).", min=0),
    browser: bool = typer.Option(
        True, "--browser/--no-browser", help="Open the page in the default browser."
    ),
    rebuild: bool = typer.Option(
        False, "--rebuild", help="Redraw report.html even if the run already has one."
    ),
) -> None:
    """Serve a run's report.html on localhost and open it (Ctrl-C stops the server).

    report.html is written first when the run has none (runs made with --no-pictures, or
    before their program wrote one).
    """
    import webbrowser

    from seminspect.core.errors import InvalidInputError
    from seminspect.report.html import REPORT_FILE, write_report

    if not run_dir.is_dir():
        raise InvalidInputError(f"{run_dir} is not a directory")
    if rebuild or not (run_dir / REPORT_FILE).is_file():
        with console.status("drawing report.html"):
            write_report(run_dir)
    try:
        server = make_server(run_dir.resolve(), port)
    except OSError as exc:
        raise InvalidInputError(f"cannot serve on port {port}: {exc.strerror}") from None
    url = f"http://127.0.0.1:{server.server_address[1]}/{REPORT_FILE}"
    console.print(f"serving {run_dir} at {url} (Ctrl-C to stop)", highlight=False)
    if browser:
        webbrowser.open(url)
    with server:
        try:
            server.serve_forever()
        except KeyboardInterrupt:
            console.print("stopped")
