"""``seminspect view``: open a run's report in the browser, served from localhost.

viser (spark-dsg's live viewer; 1.1.1 when this was written) needs rich < 15, which conflicts
with the rich 15 seminspect's environment carries, so the viewer is the run's ``report.html``
(plotly, turnable and queryable in 3D) served by the standard library's HTTP server on
127.0.0.1 only. ``--screenshot FILE`` instead draws the page in headless Chromium and writes
its picture (:mod:`seminspect.report.browser`), for machines without a display and for CI.
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
    screenshot: Path | None = typer.Option(
        None,
        "--screenshot",
        help="Write a PNG of the whole page, drawn in headless Chromium, to this file instead "
        "of serving it (needs playwright: pip install 'seminspect[view]', and a Chromium).",
        metavar="FILE",
    ),
) -> None:
    """Serve a run's report.html on localhost and open it (Ctrl-C stops the server), or
    with --screenshot write a picture of it and exit.

    report.html is written first when the run has none (runs made with --no-pictures, or
    before their program wrote one).
    """
    import webbrowser

    from seminspect.core.errors import InvalidInputError
    from seminspect.report.html import REPORT_FILE, write_report

    if not run_dir.is_dir():
        raise InvalidInputError(f"{run_dir} is not a directory")
    if screenshot is not None:
        _check_screenshot_file(screenshot)
    if rebuild or not (run_dir / REPORT_FILE).is_file():
        with console.status("drawing report.html"):
            write_report(run_dir)
    if screenshot is not None:
        _write_screenshot(run_dir / REPORT_FILE, screenshot)
        return
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


def _check_screenshot_file(file: Path) -> None:
    """Refuse, before any drawing, a picture that could not be written or has no browser."""
    from seminspect.core.errors import InvalidInputError
    from seminspect.report.browser import playwright_api, require_chromium

    if file.suffix.lower() != ".png":
        raise InvalidInputError(f"--screenshot {file}: the picture is a PNG; name it *.png")
    if not file.parent.is_dir():
        raise InvalidInputError(f"--screenshot {file}: folder {file.parent} does not exist")
    if file.is_dir():
        raise InvalidInputError(f"--screenshot {file} is a directory")
    playwright_api()
    require_chromium()


def _write_screenshot(report: Path, file: Path) -> None:
    """The picture, and a warning line for each error the page logged (it may show less)."""
    import warnings

    from seminspect.report.browser import screenshot

    with console.status("drawing report.html in headless Chromium"):
        errors = screenshot(report, file)
    for error in errors:
        warnings.warn(f"{report}: the page logged an error: {error}", stacklevel=1)
    console.print(f"wrote {file}", highlight=False, soft_wrap=True)
