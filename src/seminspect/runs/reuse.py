"""Whether a stored run can stand for a new one, and what a stopped run would run again.

A run is reused only when it completed, ran exactly the configuration asked for, holds the files
the caller needs, and was made by the same code and libraries on the same kind of CPU
(:mod:`seminspect.core.provenance`): anything else could give other figures.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import read_versioned_json
from seminspect.core.provenance import code_differences, code_version
from seminspect.runs.directory import CONFIG_FORMAT, read_run_config
from seminspect.runs.lock import RunDirectoryInUseError
from seminspect.runs.status import RunStatus, read_run_status


@dataclass(frozen=True)
class Reuse:
    """Whether a stored run can stand for a new one; false with the reason when it cannot."""

    reason: str = ""

    def __bool__(self) -> bool:
        return not self.reason


def reusable_run(run_dir: Path, config: Mapping[str, Any], needs: Sequence[str] = ()) -> Reuse:
    """Whether ``run_dir`` holds a completed run of exactly ``config`` (as the program records
    it in ``config.json``) with the files ``needs``, made by the same code and libraries as
    this process on the same kind of CPU (the reason when not)."""
    try:
        status = read_run_status(run_dir)
        document = read_versioned_json(run_dir / "config.json", CONFIG_FORMAT, [1])
    except FileFormatError as exc:
        return Reuse(f"no readable run: {exc}")
    return Reuse(_why_not_reusable(run_dir, status, document, config, needs))


def _why_not_reusable(
    run_dir: Path,
    status: RunStatus,
    document: dict[str, Any],
    config: Mapping[str, Any],
    needs: Sequence[str],
) -> str:
    if status.state != "completed":
        return f"{run_dir} is {status.state}, not completed"
    changed = _changed_settings(document["config"], config)
    if changed:
        return f"{run_dir} ran another configuration ({', '.join(changed)})"
    missing = [name for name in needs if not (run_dir / name).is_file()]
    if missing:
        return f"{run_dir} has no {', '.join(missing)}"
    if "code" not in document:
        return f"{run_dir} does not record the code that made it"
    differences = code_differences(document["code"], code_version())
    return (
        f"{run_dir} was made by other code or on another kind of machine: {'; '.join(differences)}"
        if differences
        else ""
    )


def _changed_settings(stored: Mapping[str, Any], wanted: Mapping[str, Any]) -> list[str]:
    keys = sorted(set(stored) | set(wanted))
    return [
        f"{k}: {stored.get(k)!r} -> {wanted.get(k)!r}"
        for k in keys
        if stored.get(k) != wanted.get(k)
    ]


def resumable_config(run_dir: Path) -> dict[str, Any]:
    """The configuration of a run that stopped before completing, to run again from the start;
    :class:`InvalidInputError` saying why when there is nothing to resume."""
    if not (run_dir / "config.json").is_file():
        raise InvalidInputError(f"{run_dir} is not a run directory (no config.json)")
    config = read_run_config(run_dir)
    try:
        status = read_run_status(run_dir)
    except FileFormatError:
        return config  # killed before its first status: nothing ran yet
    if status.state == "completed":
        raise InvalidInputError(
            f"{run_dir} holds a completed run; nothing to resume (run it again with --out)"
        )
    if status.state == "running":
        raise RunDirectoryInUseError(
            f"{run_dir} is being written by process {status.pid} on {status.host}; "
            "wait for it to end or stop it first"
        )
    return config
