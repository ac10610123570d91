"""Stop signals as exceptions: Ctrl-C (SIGINT) and SIGTERM end work the same way.

SIGTERM is what ``timeout``, systemd, ``docker stop`` and CI cancellation send. Python's default
is to die on the spot, leaving whatever was being written claiming to be in progress; inside
:func:`stop_on_signals` both signals raise :class:`Interrupted` instead, so ``finally`` blocks
record why the work stopped. :func:`deferred_signals` holds them back for a few lines that must
not be cut in half (the last status of a run directory). A signal that arrives while numba
compiles a kernel, or while a compiled kernel calls back into numba's Python code, is delivered
again once it has left numba: numba drops an exception raised in its callbacks (a compiled call
then fails with ``SystemError``) or leaves LLVM half-done (a crash follows).
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
from collections.abc import Iterator
from pathlib import Path
from types import FrameType

#: The signals that ask a run to stop, and how a person would name them.
STOP_SIGNALS: dict[int, str] = {
    signal.SIGINT: "interrupted by the operator (Ctrl-C)",
    signal.SIGTERM: "stopped by SIGTERM",
}


class Interrupted(KeyboardInterrupt):
    """Raised when a stop signal arrives; a ``KeyboardInterrupt`` so existing handlers apply."""

    def __init__(self, signum: int = signal.SIGINT) -> None:
        super().__init__(signum)
        self.signum = signum

    @property
    def exit_code(self) -> int:
        """The shell's convention: 128 plus the signal number (130 for Ctrl-C, 143 for SIGTERM)."""
        return 128 + self.signum

    def describe(self) -> str:
        return STOP_SIGNALS.get(self.signum, f"stopped by signal {self.signum}")


def as_interrupted(exc: KeyboardInterrupt) -> Interrupted:
    """The stop behind ``exc``. A plain ``KeyboardInterrupt`` is the last stop signal that
    :func:`stop_on_signals` raised (a library such as Ray raises its own ``KeyboardInterrupt``
    in place of the one it caught), else a Ctrl-C (Python's own handler)."""
    if isinstance(exc, Interrupted):
        return exc
    handler = _Installed.handler
    return Interrupted(handler.raised if handler and handler.raised else signal.SIGINT)


class _Handler:
    """Raise :class:`Interrupted`, or remember the signal while raising is deferred."""

    def __init__(self) -> None:
        self.deferring = 0
        self.pending: int | None = None
        self.raised: int | None = None  # the last signal raised as Interrupted

    def __call__(self, signum: int, frame: FrameType | None) -> None:
        if self.deferring:
            self.pending = self.pending or signum
            return
        if _numba_compiling():
            _redeliver(signum)  # raising in LLVM's callbacks would crash: ask again shortly
            return
        if _inside_numba(frame):
            self._raise_on_leaving_numba(signum)
            return
        self.raise_stop(signum)

    def raise_stop(self, signum: int) -> None:
        self.raised = signum
        raise Interrupted(signum)

    def _raise_on_leaving_numba(self, signum: int) -> None:
        """Raise at the main thread's first call or return outside numba's code.

        Timing the signal again would not do: a kernel spends its time in compiled code, and
        the first Python to run when it ends is numba's own again.
        """

        def on_event(frame: FrameType, event: str, arg: object) -> None:
            if _inside_numba(frame):
                return
            sys.setprofile(None)  # a profiler set before is dropped: Python drops one that raises
            if self.deferring:
                self.pending = self.pending or signum
                return
            self.raise_stop(signum)

        sys.setprofile(on_event)


#: How long a stop signal waits before it is delivered again while numba compiles (s).
REDELIVERY_DELAY = 0.05


def _numba_compiling() -> bool:
    """Whether numba is compiling now (checked without importing numba)."""
    lock_module = sys.modules.get("numba.core.compiler_lock")
    return lock_module is not None and lock_module.global_compiler_lock.is_locked()


def _inside_numba(frame: FrameType | None) -> bool:
    """Whether numba's or llvmlite's Python code is on the stack ending at ``frame``.

    Compiled kernels call back into Python (to rebuild constants, to box results) through code
    that ignores an exception raised there.
    """
    packages = tuple(
        f"{Path(module.__file__).parent}{os.sep}"
        for name in ("numba", "llvmlite")
        if (module := sys.modules.get(name)) is not None and module.__file__
    )
    while packages and frame is not None:
        if frame.f_code.co_filename.startswith(packages):
            return True
        frame = frame.f_back
    return False


def _redeliver(signum: int) -> None:
    timer = threading.Timer(REDELIVERY_DELAY, os.kill, (os.getpid(), signum))
    timer.daemon = True
    timer.start()


class _Installed:
    """The handler :func:`stop_on_signals` installed, if any (one per process)."""

    handler: _Handler | None = None


@contextlib.contextmanager
def stop_on_signals() -> Iterator[None]:
    """Turn SIGINT and SIGTERM into :class:`Interrupted` inside the block.

    Outside the main thread signal handlers cannot be installed; the block then runs unchanged
    (Python still raises ``KeyboardInterrupt`` for Ctrl-C in the main thread).
    """
    if threading.current_thread() is not threading.main_thread() or _Installed.handler:
        yield
        return
    handler = _Handler()
    previous = {signum: signal.signal(signum, handler) for signum in STOP_SIGNALS}
    _Installed.handler = handler
    try:
        yield
    finally:
        _Installed.handler = None
        for signum, old in previous.items():
            signal.signal(signum, old)


@contextlib.contextmanager
def deferred_signals() -> Iterator[None]:
    """Hold stop signals back until the block ends, then raise the first one that arrived."""
    handler = _Installed.handler
    if handler is None:
        yield
        return
    handler.deferring += 1
    try:
        yield
    finally:
        handler.deferring -= 1
        if not handler.deferring and handler.pending is not None:
            signum, handler.pending = handler.pending, None
            handler.raise_stop(signum)
