"""A run's ``status.json``: its state and why, judged against the living.

A running writer keeps a heartbeat in the file (:class:`~seminspect.runs.directory.RunDirectory`);
:func:`read_run_status` reports a run whose writer is gone as ``dead`` and one whose heartbeat
stopped as ``abandoned``.
"""

from __future__ import annotations

import os
import socket
import time
from dataclasses import dataclass
from pathlib import Path

from seminspect.core.io import read_versioned_json

STATUS_FORMAT = "seminspect.run-status"
#: Seconds between heartbeats, and the age after which a silent run counts as abandoned.
HEARTBEAT_S = 5.0
STALE_AFTER_S = 120.0


@dataclass(frozen=True)
class RunStatus:
    """What ``status.json`` says, judged against the living: ``state`` is ``dead`` when the
    writing process is gone and ``abandoned`` when its heartbeat stopped; ``recorded`` is the
    state the file itself holds."""

    state: str
    recorded: str
    reason: str
    pid: int | None
    host: str | None
    heartbeat: float | None


def read_run_status(run_dir: Path) -> RunStatus:
    """The state of the run in ``run_dir``, a ``running`` one checked for a live writer."""
    status = read_versioned_json(run_dir / "status.json", STATUS_FORMAT, [1])
    recorded, reason = str(status.get("state")), str(status.get("reason", ""))
    pid, host, beat = status.get("pid"), status.get("host"), status.get("heartbeat")
    state = recorded
    if recorded == "running":
        if host == socket.gethostname() and isinstance(pid, int) and not _process_alive(pid):
            state, reason = "dead", f"process {pid} stopped without recording why (killed?)"
        elif not isinstance(beat, int | float) or time.time() - beat > STALE_AFTER_S:
            state = "abandoned"
            reason = f"no heartbeat from process {pid} on {host} for over {STALE_AFTER_S:.0f} s"
    return RunStatus(state, recorded, reason, pid, host, beat)


def _process_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # alive, but another user's
        return True
    return True
