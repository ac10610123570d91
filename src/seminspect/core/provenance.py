"""Which code made a result: the package version, a hash of its source, the git revision and
the versions of the libraries whose behaviour shapes the numbers.

A run directory records this so a later reader can tell whether a stored run still stands for
the current code (see ``missions.rundir.reusable_run``).
"""

from __future__ import annotations

import functools
import hashlib
import subprocess
from importlib import metadata
from pathlib import Path
from typing import Any

import seminspect

#: Distributions (PyPI names) whose versions are recorded; absent ones are recorded as None.
DEPENDENCIES = (
    "numpy",
    "scipy",
    "numba",
    "trimesh",
    "embreex",
    "networkx",
    "opencv-python-headless",
    "shapely",
    "scikit-learn",
    "scikit-image",
    "pydantic",
)


def package_root() -> Path:
    """The directory of the imported ``seminspect`` package."""
    return Path(seminspect.__file__).resolve().parent


@functools.cache
def source_hash(root: Path | None = None) -> str:
    """SHA-256 over the relative path and bytes of every ``.py`` file under the package."""
    base = root or package_root()
    digest = hashlib.sha256()
    for path in sorted(base.rglob("*.py")):
        digest.update(path.relative_to(base).as_posix().encode() + b"\0")
        digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest()


@functools.cache
def git_revision(root: Path | None = None) -> str | None:
    """``HEAD`` of the repository holding the package (``+dirty`` with local changes), if any."""
    where = root or package_root()
    try:
        head = _git(where, "rev-parse", "HEAD")
        dirty = _git(where, "status", "--porcelain", "--untracked-files=no", ".")
    except (OSError, subprocess.SubprocessError):
        return None
    return head + ("+dirty" if dirty else "")


def _git(where: Path, *args: str) -> str:
    done = subprocess.run(
        ["git", *args], cwd=where, capture_output=True, text=True, timeout=5, check=True
    )
    return done.stdout.strip()


def dependency_versions() -> dict[str, str | None]:
    versions: dict[str, str | None] = {}
    for name in DEPENDENCIES:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = None
    return versions


def code_version() -> dict[str, Any]:
    """Everything :mod:`seminspect.core.provenance` records, as a JSON-ready dict."""
    return {
        "seminspect": seminspect.__version__,
        "source_sha256": source_hash(),
        "git": git_revision(),
        "dependencies": dependency_versions(),
    }


def code_differences(recorded: dict[str, Any], current: dict[str, Any]) -> list[str]:
    """What differs between two :func:`code_version` records, one phrase per difference."""
    differences = []
    if recorded.get("source_sha256") != current.get("source_sha256"):
        differences.append(
            f"seminspect source changed ({_short(recorded.get('source_sha256'))} -> "
            f"{_short(current.get('source_sha256'))})"
        )
    old, new = recorded.get("dependencies") or {}, current.get("dependencies") or {}
    for name in sorted(set(old) | set(new)):
        if old.get(name) != new.get(name):
            differences.append(f"{name} {old.get(name)} -> {new.get(name)}")
    return differences


def _short(digest: Any) -> str:
    return str(digest)[:12] if digest else "unrecorded"
