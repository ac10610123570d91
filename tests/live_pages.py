"""Watching a live view in headless Chromium while a run goes on: the browser tests' one way.

The page is opened first; the run starts in a thread once the page's stream is connected (as
``--view`` waits for a browser). Every state the page draws is recorded in the page itself, so
a run that is over in seconds is still seen state by state.
"""

from __future__ import annotations

import json
import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from seminspect.report.browser import find_chromium, open_page
from seminspect.report.live_server import LiveServer

#: Keeps (the page's clock, points of the path) of every state drawn, in ``window.drawn``.
RECORD_STATES = """() => {
  window.drawn = [];
  const gd = document.getElementById('live-scene');
  new MutationObserver(() => window.drawn.push([Number(document.body.dataset.simTime),
      gd._fullData.find((t) => t.meta.trace === 'path')._length ?? 0]))
    .observe(document.body, {attributes: true, attributeFilter: ['data-sim-time']});
}"""
#: Points plotly drew in each trace of the scene (a mesh's vertices).
DRAWN = """() => Object.fromEntries(document.getElementById('live-scene')._fullData
  .map((t) => [t.meta.trace, t._length ?? t.x?.length ?? 0]))"""


class RecordingServer:
    """What a feed needs of a live server, keeping what was sent as the page would parse it:
    the scene, the states (``sent``) and the other events' messages (``events``)."""

    def __init__(self) -> None:
        self.scene: dict | None = None
        self.sent: list[dict] = []
        self.events: dict[str, list[dict]] = {}

    def ready(self) -> bool:
        return True

    def set_scene(self, scene: dict) -> None:
        self.scene = json.loads(json.dumps(scene, allow_nan=False))

    def send(self, message: dict, event: str = "message") -> None:
        parsed = json.loads(json.dumps(message, allow_nan=False))
        if event == "message":
            self.sent.append(parsed)
        else:
            self.events.setdefault(event, []).append(parsed)


@dataclass
class Watched:
    """What the page showed: each trace's points at the end, every state's (clock, path
    points), the picture, the status table's text, the console's errors, and the values of
    the caller's extra expressions."""

    final: dict[str, int]
    states: list[tuple[float, int]]
    camera: str | None
    status: str
    errors: list[str]
    values: dict[str, Any] = field(default_factory=dict)


def watch_in_browser(
    page: str,
    run: Callable[[LiveServer], object],
    final_text: str,
    screenshot: Path,
    extra: Mapping[str, str] = {},
) -> Watched:
    """Serve ``page``, open it, run ``run(server)`` once it listens, and read the page after
    ``final_text`` appears (skips without Chromium or playwright)."""
    if find_chromium() is None:
        pytest.skip("no Chromium found (apt-get install chromium, or set $SEMINSPECT_CHROMIUM)")
    pytest.importorskip("playwright.sync_api", reason="playwright is not installed")
    with LiveServer(page, port=0, period_s=0.2) as server:
        runner = threading.Thread(target=lambda: server.wait_for_client(60) and run(server))
        with open_page(server.url) as (browser, errors):
            browser.evaluate(RECORD_STATES)
            runner.start()
            browser.wait_for_selector(f"text={final_text}", timeout=120_000)
            watched = Watched(
                final=browser.evaluate(DRAWN),
                states=[tuple(s) for s in browser.evaluate("() => window.drawn")],
                camera=browser.get_attribute("#camera", "src"),
                status=browser.inner_text("#status"),
                errors=errors,
                values={name: browser.evaluate(js) for name, js in extra.items()},
            )
            browser.screenshot(path=str(screenshot))
        runner.join(30)
    return watched


def grew(states: list[tuple[float, int]]) -> bool:
    """Several states drawn, the clock and the path only ever moving on, and both moved."""
    times = [t for t, _ in states]
    paths = [p for _, p in states]
    return (
        len(states) >= 3
        and times == sorted(times)
        and paths == sorted(paths)
        and times[0] < times[-1]
        and paths[0] < paths[-1]
    )
