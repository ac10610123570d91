"""Run directories, shared by every program: one locked writer, a heartbeat, a truthful last
status, reuse of a stored run, and sweeps of many runs into one table. Depends only on
:mod:`seminspect.core`; each program names its own files (:class:`RunLayout`) and metrics."""

from seminspect.runs.conduct import RunEnd, conduct_run
from seminspect.runs.directory import RunDirectory, RunLayout, read_run_config
from seminspect.runs.lock import RunDirectoryInUseError
from seminspect.runs.reuse import Reuse, resumable_config, reusable_run
from seminspect.runs.status import RunStatus, read_run_status
from seminspect.runs.trajectory import load_trajectory

__all__ = [
    "Reuse",
    "RunDirectory",
    "RunDirectoryInUseError",
    "RunEnd",
    "RunLayout",
    "RunStatus",
    "conduct_run",
    "load_trajectory",
    "read_run_config",
    "read_run_status",
    "resumable_config",
    "reusable_run",
]
