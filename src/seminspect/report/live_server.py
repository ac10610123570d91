"""A live view's server: one page and a stream of JSON states, on localhost, standard library only.

The page is served at ``/``, plotly.js at ``/plotly.min.js`` (from the plotly package, so the
page needs no network) and the states at ``/events`` as Server-Sent Events. The server keeps
the newest message of each event name: ``scene`` (what does not change during a run), the
state (the default event) and any part that changes more slowly and is sent less often (a
map). A client gets each name's newest message it has not had, oldest first, so one that
connects late, or misses messages while it draws, loses only the ones in between. A client
that goes away mid-run ends only its own stream.

Sending is paced by :meth:`LiveServer.ready`: a program builds a state only when a client is
connected and the last one is at least ``period_s`` old, so a run nobody watches pays nothing.
"""

from __future__ import annotations

import functools
import http.server
import json
import threading
import time
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from typing import Any

from plotly.offline import get_plotlyjs

from seminspect.core.errors import InvalidInputError

#: Seconds a stream waits for a new state before a keep-alive comment.
KEEP_ALIVE_S = 10.0


class LiveServer:
    """A page and its Server-Sent Events on ``host:port`` (port 0: any free one).

    Args:
        page: the page's HTML.
        port: the TCP port; one in use is refused with a clear error.
        period_s: the least wall time between two states (:meth:`ready`).
        host: the interface; localhost by default, so nothing leaves the machine.
    """

    def __init__(
        self, page: str, port: int = 8765, *, period_s: float = 0.5, host: str = "127.0.0.1"
    ) -> None:
        self.period_s = period_s
        self._page = page.encode()
        self._changed = threading.Condition()
        #: The newest message of each event name, numbered in the order they were sent.
        self._latest: dict[str, tuple[int, bytes]] = {}
        self._sequence = 0
        self._closed = False
        self._clients = 0
        self._sent_at = -float("inf")
        try:
            self._httpd = http.server.ThreadingHTTPServer((host, port), _handler(self))
        except OSError as exc:
            raise InvalidInputError(
                f"cannot serve the live view on {host}:{port}: {exc.strerror or exc}"
            ) from None
        self._httpd.daemon_threads = True
        self._thread = threading.Thread(
            target=self._httpd.serve_forever, name="live-view", daemon=True
        )
        self._thread.start()

    @property
    def url(self) -> str:
        host, port = self._httpd.server_address[:2]
        return f"http://{host!s}:{port}/"

    @property
    def clients(self) -> int:
        """Streams open now."""
        return self._clients

    def ready(self) -> bool:
        """Whether a state is wanted: a client listens and the last state is old enough."""
        return self._clients > 0 and time.monotonic() - self._sent_at >= self.period_s

    def set_scene(self, scene: Mapping[str, Any]) -> None:
        """What every client gets first, as the ``scene`` event (the run's static part)."""
        self.send(scene, event="scene")

    def send(self, message: Mapping[str, Any], event: str = "message") -> None:
        """The newest message of an event name (``message``: the state :meth:`ready` paces;
        others for parts that change more slowly), for every client: one that is still
        drawing gets the newest of each name next, oldest first."""
        encoded = _encoded(message)
        with self._changed:
            self._sequence += 1
            self._latest[event] = (self._sequence, encoded)
            if event == "message":
                self._sent_at = time.monotonic()
            self._changed.notify_all()

    def wait_for_client(self, timeout_s: float) -> bool:
        """Wait until a client is connected (True) or ``timeout_s`` has passed (False)."""
        with self._changed:
            return self._changed.wait_for(lambda: self._clients > 0, timeout_s)

    def close(self, grace_s: float = 2.0) -> None:
        """End every stream (each gets the last state first, within ``grace_s``), stop serving."""
        if self._closed:
            return
        with self._changed:
            self._closed = True
            self._changed.notify_all()
            self._changed.wait_for(lambda: self._clients == 0, grace_s)
        self._httpd.shutdown()
        self._httpd.server_close()

    def __enter__(self) -> LiveServer:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    @contextmanager
    def _client(self) -> Iterator[None]:
        with self._changed:
            self._clients += 1
            self._changed.notify_all()
        try:
            yield
        finally:
            with self._changed:
                self._clients -= 1
                self._changed.notify_all()

    def _messages(self) -> Iterator[bytes]:
        """One client's stream: the newest message of each name it has not had, oldest first,
        keep-alives in between; what was sent before :meth:`close` still goes out."""
        seen = 0
        while True:
            with self._changed:
                self._changed.wait_for(functools.partial(self._has_news, seen), KEEP_ALIVE_S)
                news = sorted((n, e, m) for e, (n, m) in self._latest.items() if n > seen)
                closed = self._closed
            for number, event, message in news:
                seen = max(seen, number)
                name = b"" if event == "message" else b"event: " + event.encode() + b"\n"
                yield name + b"data: " + message + b"\n\n"
            if closed and not news:
                return
            if not news:
                yield b": keep-alive\n\n"

    def _has_news(self, seen: int) -> bool:
        return self._closed or self._sequence > seen

    @functools.cached_property
    def _plotly_js(self) -> bytes:
        return get_plotlyjs().encode()


def _encoded(message: Mapping[str, Any]) -> bytes:
    """One line of JSON (an SSE data field may not hold a newline)."""
    return json.dumps(message, separators=(",", ":"), allow_nan=False).encode()


def _handler(server: LiveServer) -> type[http.server.BaseHTTPRequestHandler]:
    class Handler(http.server.BaseHTTPRequestHandler):
        def do_GET(self) -> None:
            path = self.path.split("?", 1)[0]
            if path == "/events":
                self._stream()
            elif path in {"/", "/index.html"}:
                self._reply(server._page, "text/html; charset=utf-8")
            elif path == "/plotly.min.js":
                self._reply(server._plotly_js, "application/javascript")
            elif path == "/favicon.ico":  # browsers ask; no icon is not an error
                self.send_response(204)
                self.end_headers()
            else:
                self.send_error(404)

        def _reply(self, body: bytes, content_type: str) -> None:
            self.send_response(200)
            self.send_header("Content-Type", content_type)
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def _stream(self) -> None:
            self.send_response(200)
            self.send_header("Content-Type", "text/event-stream")
            self.send_header("Cache-Control", "no-cache")
            self.end_headers()
            try:
                with server._client():
                    for message in server._messages():
                        self.wfile.write(message)
                        self.wfile.flush()
            except (BrokenPipeError, ConnectionResetError):
                pass  # the client went away: only its stream ends
            self.close_connection = True

        def log_message(self, format: str, *args: object) -> None:
            """Requests are not worth a line each on the console."""

    return Handler
