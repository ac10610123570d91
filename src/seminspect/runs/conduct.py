"""Doing a run's work and always leaving a complete run directory with a truthful last status.

:func:`conduct_run` is the one shape every program's run takes: the work, then its outputs
whatever happened to the work, then the last status, which names what was not written when a
stop cut the outputs short, and the file that could not be written when the disk is full.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from seminspect.core.errors import SeminspectError
from seminspect.core.interrupts import Interrupted, as_interrupted, deferred_signals
from seminspect.runs.directory import RunDirectory, failure_reason


@dataclass
class RunEnd:
    """How a run ended: its last state, why, and the error or stop signal behind it."""

    state: str = "completed"
    reason: str = ""
    error: Exception | None = None
    stop: Interrupted | None = field(default=None, repr=False)

    @property
    def signum(self) -> int | None:
        """The signal that stopped the run, if one did."""
        return self.stop.signum if self.stop else None


def conduct_run(
    run: RunDirectory,
    work: Callable[[], str],
    write_outputs: Callable[[RunEnd], None],
    *,
    expected: Sequence[str],
    what: str,
) -> RunEnd:
    """Do ``work`` (it returns why it stopped), then ``write_outputs`` whatever happened, then
    the last status, which is truthful: a stop while writing names the ``expected`` files that
    were not written. A failure is re-raised once the directory is complete, as a
    :class:`SeminspectError` naming ``what`` failed and where the partial results are."""
    end = RunEnd()
    try:
        end.reason = work()
        run.settle_images()
    except KeyboardInterrupt as exc:
        end.stop = as_interrupted(exc)
        end.state, end.reason = "interrupted", end.stop.describe()
    except Exception as exc:
        end.state, end.reason, end.error = "failed", failure_reason(run.root, exc), exc
    try:
        run.settle_images()  # those of work that stopped early
        write_outputs(end)
    except KeyboardInterrupt as exc:
        end.stop = end.stop or as_interrupted(exc)
        end.state = "interrupted"
        stopped = f"{end.stop.describe()} while writing the outputs"
        end.reason = _cut_short(run, end.reason, stopped, expected)
    except Exception as exc:
        failure = f"finishing the run failed: {failure_reason(run.root, exc)}"
        end.state, end.reason = "failed", _cut_short(run, end.reason, failure, expected)
        end.error = end.error or exc
    with deferred_signals():  # a second signal must not cut the last status short
        run.finish(end.state, end.reason)
    if end.error is not None:
        if isinstance(end.error, SeminspectError):
            raise end.error
        raise SeminspectError(
            f"{what} failed ({end.reason}); partial results in {run.root}"
        ) from end.error
    return end


def _cut_short(run: RunDirectory, reason: str, why: str, expected: Sequence[str]) -> str:
    """The reason of a run stopped while writing its outputs, naming the ones not written."""
    missing = [name for name in expected if not run.path(name).exists()]
    note = why + (f"; not written: {', '.join(missing)}" if missing else "")
    return f"{reason}; {note}" if reason else note
