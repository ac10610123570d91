"""The live view's server: the page, the scene first, the newest state, pacing, clients that
come late or go away, a port in use, and the last state still sent on close."""

from __future__ import annotations

import json
import socket
import threading
import time
import urllib.request
from collections.abc import Callable, Iterator
from http.client import HTTPResponse

import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.report.live_server import LiveServer


@pytest.fixture
def server() -> Iterator[LiveServer]:
    with LiveServer("<p>live</p>", port=0, period_s=0.2) as live:
        yield live


def _until(condition: Callable[[], bool], timeout_s: float = 5.0) -> bool:
    deadline = time.monotonic() + timeout_s
    while not condition() and time.monotonic() < deadline:
        time.sleep(0.02)
    return condition()


def _open_stream(server: LiveServer) -> HTTPResponse:
    """A client's stream, once the server counts it."""
    before = server.clients
    stream = urllib.request.urlopen(server.url + "events", timeout=10)
    assert _until(lambda: server.clients > before)
    return stream


def _event(stream: HTTPResponse) -> tuple[str, dict]:
    """The next event of a stream: its name (``message`` by default) and its data."""
    name = "message"
    while True:
        line = stream.readline().decode().rstrip("\n")
        if line.startswith("event: "):
            name = line.removeprefix("event: ")
        elif line.startswith("data: "):
            return name, json.loads(line.removeprefix("data: "))


def test_serves_the_page_and_plotly(server: LiveServer) -> None:
    with urllib.request.urlopen(server.url, timeout=10) as page:
        assert page.read() == b"<p>live</p>"
    with urllib.request.urlopen(server.url + "plotly.min.js", timeout=10) as script:
        assert script.headers["Content-Type"] == "application/javascript"
        assert b"plotly" in script.read(100_000).lower()
    with pytest.raises(urllib.error.HTTPError, match="404"):
        urllib.request.urlopen(server.url + "nothing", timeout=10)


def test_binds_to_localhost_by_default(server: LiveServer) -> None:
    assert server.url.startswith("http://127.0.0.1:")


def test_a_client_gets_the_scene_first_then_the_newest_state(server: LiveServer) -> None:
    server.set_scene({"world": "w"})
    server.send({"t": 1})
    server.send({"t": 2})  # before anyone listens: only the newest is kept
    with _open_stream(server) as stream:
        assert _event(stream) == ("scene", {"world": "w"})
        assert _event(stream) == ("message", {"t": 2})
        server.send({"t": 3})
        assert _event(stream) == ("message", {"t": 3})


def test_ready_only_with_a_client_and_at_the_period(server: LiveServer) -> None:
    assert not server.ready()  # nobody watches: nothing is built
    assert not server.wait_for_client(0.1)
    with _open_stream(server):
        assert server.wait_for_client(0.1)
        assert server.ready()
        server.send({"t": 1})
        assert not server.ready()
        time.sleep(0.25)
        assert server.ready()


def test_a_client_that_goes_away_ends_only_its_own_stream(server: LiveServer) -> None:
    first = _open_stream(server)
    with _open_stream(server) as second:
        assert server.clients == 2
        first.close()
        for t in range(20):  # writes to the closed connection fail, and only it ends
            server.send({"t": t})
            time.sleep(0.02)
        assert _until(lambda: server.clients == 1)
        while (event := _event(second)) != ("message", {"t": 19}):
            assert event[0] == "message"


def test_close_still_sends_the_last_state(server: LiveServer) -> None:
    stream = _open_stream(server)
    received: list[tuple[str, dict]] = []
    reader = threading.Thread(target=lambda: received.append(_event(stream)))
    server.send({"final": "completed"})
    reader.start()
    server.close()
    reader.join(5)
    assert received == [("message", {"final": "completed"})]
    assert stream.read().strip() == b""  # and the stream ended
    stream.close()


def test_a_port_in_use_is_one_clear_error() -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        expected = f"cannot serve the live view on 127.0.0.1:{port}"
        with pytest.raises(InvalidInputError, match=expected):
            LiveServer("", port=port)


def test_states_must_be_finite_json(server: LiveServer) -> None:
    with pytest.raises(ValueError, match="not JSON compliant"):
        server.send({"t": float("nan")})
