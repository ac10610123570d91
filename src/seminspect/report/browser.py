"""Headless Chromium for reports: finding the browser, opening a page, taking its picture.

The browser is the system's Chromium (Debian's ``chromium`` package, or the one
``$SEMINSPECT_CHROMIUM`` names) driven by playwright; playwright's own browser download
(``playwright install``) is never needed, so this works on a machine that only has the distro's
package. playwright is an optional extra (``pip install 'seminspect[view]'``); it is imported
only when a page is opened. ``seminspect view --screenshot`` and the browser tests of
``tests/report/test_html.py`` both open pages through :func:`open_page`.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from types import ModuleType
from typing import Any

from seminspect.core.errors import SeminspectError
from seminspect.core.io import atomic_write_bytes

CHROMIUM_ENV = "SEMINSPECT_CHROMIUM"
#: Headless, and quiet: no sandbox (containers and CI run as root), no GPU, no network of its own.
CHROMIUM_ARGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
)
VIEWPORT = {"width": 1400, "height": 1000}
PLAYWRIGHT_HINT = "pip install 'seminspect[view]'"
CHROMIUM_HINT = f"apt-get install chromium, or set ${CHROMIUM_ENV} to a Chromium binary"
#: Waits until every plotly figure of the page has been laid out (a 3D one has its scene, a
#: 2D one its x axis): before that a picture would show empty boxes.
FIGURES_DRAWN = """() => [...document.querySelectorAll('.plotly-graph-div, .js-plotly-plot')].every(
  (gd) => gd._fullLayout?.scene !== undefined || gd._fullLayout?.xaxis !== undefined)"""


def find_chromium() -> str | None:
    """A Chromium binary: ``$SEMINSPECT_CHROMIUM``, Debian's package, or one on PATH."""
    for candidate in (os.environ.get(CHROMIUM_ENV), "/usr/bin/chromium"):
        if candidate and Path(candidate).is_file():
            return candidate
    return shutil.which("chromium") or shutil.which("chromium-browser")


def playwright_api() -> ModuleType:
    """``playwright.sync_api``, or a one-line error that says how to install it."""
    try:
        from playwright import sync_api  # noqa: PLC0415 - an optional extra, loaded when used
    except ImportError:
        raise SeminspectError(
            f"taking a picture of a page needs playwright, which is not installed: "
            f"{PLAYWRIGHT_HINT}"
        ) from None
    return sync_api


def require_chromium() -> str:
    """:func:`find_chromium`, or a one-line error that says how to get one."""
    found = find_chromium()
    if found is None:
        raise SeminspectError(f"no Chromium found: {CHROMIUM_HINT}")
    return found


@contextmanager
def open_page(url: str, *, timeout_s: float = 60.0) -> Iterator[tuple[Any, list[str]]]:
    """``(page, console errors)`` of ``url`` in headless Chromium once its plotly figures are
    drawn; the errors list keeps filling while the block runs (page errors included)."""
    sync_api = playwright_api()
    chromium = require_chromium()
    errors: list[str] = []
    with sync_api.sync_playwright() as driver:
        try:
            browser = driver.chromium.launch(executable_path=chromium, args=list(CHROMIUM_ARGS))
        except sync_api.Error as exc:
            raise SeminspectError(f"{chromium} did not start: {_first_line(exc)}") from None
        try:
            page = browser.new_page(viewport=VIEWPORT)
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda exc: errors.append(str(exc)))
            page.goto(url)
            try:
                page.wait_for_function(FIGURES_DRAWN, timeout=timeout_s * 1000)
            except sync_api.TimeoutError:
                raise SeminspectError(
                    f"{url}: its figures were not drawn within {timeout_s:g} s"
                ) from None
            yield page, errors
        finally:
            browser.close()


def screenshot(page_file: Path, out: Path, *, timeout_s: float = 60.0) -> list[str]:
    """A PNG of the whole page (``file://``, as a reader opens it), written atomically to
    ``out``; returns what the page logged as errors, for the caller to pass on."""
    with open_page(page_file.resolve().as_uri(), timeout_s=timeout_s) as (page, errors):
        png = page.screenshot(full_page=True, type="png")
    atomic_write_bytes(out, png)
    return errors


def _first_line(exc: BaseException) -> str:
    lines = str(exc).strip().splitlines()
    return lines[0] if lines else type(exc).__name__
