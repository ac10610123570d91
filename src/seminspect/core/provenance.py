"""Which code made a result: the package version, a hash of its source, the git revision, the
versions of the libraries whose behaviour shapes the numbers and the machine's floating-point
paths.

A run directory records this so a later reader can tell whether a stored run still stands for
the current code on the current machine (see ``missions.rundir.reusable_run``).
"""

from __future__ import annotations

import functools
import hashlib
import platform
import subprocess
from importlib import metadata
from pathlib import Path
from typing import Any

from threadpoolctl import threadpool_info

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


#: x86 instruction sets that change floating-point results, widest first (``/proc/cpuinfo``
#: flag names).
_SIMD_LEVELS = ("avx512f", "avx2", "avx", "sse4_2")


@functools.cache
def numeric_platform() -> dict[str, str]:
    """The machine's floating-point paths: what a run's figures depend on beside the code,
    the library versions and the seed.

    Embree intersects rays with the widest SIMD instruction set the CPU offers, refining the
    CPU's own reciprocal estimates (which differ between vendors); OpenBLAS picks its kernels
    by CPU model. Runs of the same code and seed agree bit for bit on machines that agree on
    every field; elsewhere their distances differ in the last bits, and a mission's path then
    drifts apart (docs/reproduction.md, "Reproducing on another machine").
    """
    import numpy  # noqa: F401, PLC0415 - loads the BLAS that threadpool_info looks for

    vendor, flags = _cpu_identity()
    simd = next((level for level in _SIMD_LEVELS if level in flags), "none" if flags else "")
    blas = _numpy_blas_architecture()
    return {
        "machine": platform.machine(),
        "cpu_vendor": vendor or platform.processor(),
        "simd": simd,
        "blas_kernels": blas,
    }


def _numpy_blas_architecture() -> str:
    """The kernels of the BLAS numpy calls: OpenCV ships an OpenBLAS of its own, and which of
    the two a process loaded first must not change the answer."""
    blas = [lib for lib in threadpool_info() if lib["user_api"] == "blas"]
    numpy_first = sorted(blas, key=lambda lib: "numpy" not in Path(lib["filepath"]).parent.name)
    return str(numpy_first[0].get("architecture", "")) if numpy_first else ""


def _cpu_identity() -> tuple[str, set[str]]:
    """The CPU's vendor and feature flags as Linux reports them (empty elsewhere)."""
    try:
        text = Path("/proc/cpuinfo").read_text(encoding="utf-8", errors="replace")
    except OSError:
        return "", set()
    fields: dict[str, str] = {}
    for line in text.splitlines():
        key, _, value = line.partition(":")
        fields.setdefault(key.strip(), value.strip())
    return fields.get("vendor_id", ""), set(fields.get("flags", "").split())


def code_version() -> dict[str, Any]:
    """Everything :mod:`seminspect.core.provenance` records, as a JSON-ready dict."""
    return {
        "seminspect": seminspect.__version__,
        "source_sha256": source_hash(),
        "git": git_revision(),
        "dependencies": dependency_versions(),
        "platform": numeric_platform(),
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
    # Records from before the platform was recorded cannot tell; they are taken at their word.
    was, now = recorded.get("platform"), current.get("platform")
    if was and now and was != now:
        differences.append(f"machine {platform_label(was)} -> {platform_label(now)}")
    return differences


def platform_label(fields: dict[str, str]) -> str:
    """A :func:`numeric_platform` record in a few words, e.g. ``x86_64 GenuineIntel avx512f``."""
    return " ".join(
        fields[key] for key in ("machine", "cpu_vendor", "simd", "blas_kernels") if fields.get(key)
    )


def _short(digest: Any) -> str:
    return str(digest)[:12] if digest else "unrecorded"
