"""Which code made a result: the package version, a hash of its source, the git revision, the
versions of the libraries whose behaviour shapes the numbers and the machine's floating-point
paths.

A run directory records this so a later reader can tell whether a stored run still stands for
the current code on the current machine (see ``runs.reuse.reusable_run``).
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
    by CPU model. The named fields say which paths were taken where they can be read; the
    ``fingerprint`` hashes what those paths compute (:func:`numeric_fingerprint`), so two
    machines whose paths differ in a way no field names still differ. Runs of the same code
    and seed agree bit for bit on machines that agree on every field; elsewhere their
    distances differ in the last bits, and a mission's path then drifts apart
    (docs/reproduction.md, "Reproducing on another machine").
    """
    import numpy  # noqa: F401, PLC0415 - loads the BLAS that threadpool_info looks for

    fields = _cpu_identity()
    flags = set(fields.get("flags", "").split())
    simd = next((level for level in _SIMD_LEVELS if level in flags), "none" if flags else "")
    return {
        "machine": platform.machine(),
        "cpu_vendor": fields.get("vendor_id") or platform.processor(),
        "cpu_model": fields.get("model name", ""),
        "simd": simd,
        "blas_kernels": _numpy_blas_architecture(),
        "fingerprint": numeric_fingerprint(),
    }


#: Rays of the fingerprint's Embree cast, and the side of its BLAS products.
_FINGERPRINT_RAYS = 4096
_FINGERPRINT_MATRIX = 96


def numeric_fingerprint() -> str:
    """A short hash of a fixed Embree ray cast and fixed BLAS products, the two floating-point
    paths measured to move a mission's figures (docs/reproduction.md): machines with the same
    hash computed both bit for bit alike.

    The cast goes through ``embreex``, whose hits the missions' own Embree calls reproduce bit
    for bit (``worlds/embree.py``); the rays meet a subdivided sphere at every angle, from
    inside and outside, so that ray-triangle tests of every slope enter the hash.
    """
    import numpy as np  # noqa: PLC0415 - heavy, and only needed here
    import trimesh  # noqa: PLC0415
    from embreex import rtcore_scene  # noqa: PLC0415
    from embreex.mesh_construction import TriangleMesh  # noqa: PLC0415

    sphere = trimesh.creation.icosphere(subdivisions=3, radius=1.7)
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(scene, sphere.vertices.astype(np.float32), sphere.faces.astype(np.int32))
    rng = np.random.default_rng(20261201)
    origins = rng.uniform(-3.0, 3.0, (_FINGERPRINT_RAYS, 3)).astype(np.float32)
    directions = rng.normal(size=(_FINGERPRINT_RAYS, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    hits = scene.run(origins, directions.astype(np.float32), output=1)
    a = rng.normal(size=(_FINGERPRINT_MATRIX, _FINGERPRINT_MATRIX))
    b = rng.normal(size=(_FINGERPRINT_MATRIX, _FINGERPRINT_MATRIX))
    digest = hashlib.sha256()
    for part in (hits["tfar"], hits["primID"], a @ b, a.astype(np.float32) @ b.astype(np.float32)):
        digest.update(np.ascontiguousarray(part).tobytes())
    return digest.hexdigest()[:16]


def _numpy_blas_architecture() -> str:
    """The kernels of the BLAS numpy calls: OpenCV ships an OpenBLAS of its own, and which of
    the two a process loaded first must not change the answer."""
    blas = [lib for lib in threadpool_info() if lib["user_api"] == "blas"]
    numpy_first = sorted(blas, key=lambda lib: "numpy" not in Path(lib["filepath"]).parent.name)
    return str(numpy_first[0].get("architecture", "")) if numpy_first else ""


def _cpu_identity() -> dict[str, str]:
    """The first processor's fields (vendor, model name, feature flags) as Linux reports them
    (empty elsewhere)."""
    try:
        text = Path("/proc/cpuinfo").read_text(encoding="utf-8", errors="replace")
    except OSError:
        return {}
    fields: dict[str, str] = {}
    for line in text.splitlines():
        key, _, value = line.partition(":")
        fields.setdefault(key.strip(), value.strip())
    return fields


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
        differences.append(f"machine {platform_difference(was, now)}")
    return differences


def platform_difference(was: dict[str, str], now: dict[str, str]) -> str:
    """How two :func:`numeric_platform` records differ, field by field (``unrecorded`` where
    one of them lacks the field), e.g. ``simd avx2 -> avx512f``."""
    keys = [key for key in _PLATFORM_KEYS if key in was or key in now]
    keys += sorted((set(was) | set(now)) - set(keys))
    return ", ".join(
        f"{key} {was.get(key, 'unrecorded')} -> {now.get(key, 'unrecorded')}"
        for key in keys
        if was.get(key) != now.get(key)
    )


#: The fields of :func:`numeric_platform`, in the order labels name them.
_PLATFORM_KEYS = ("machine", "cpu_vendor", "cpu_model", "simd", "blas_kernels", "fingerprint")


def platform_label(fields: dict[str, str]) -> str:
    """A :func:`numeric_platform` record in a few words, e.g. ``x86_64 GenuineIntel avx512f
    SkylakeX`` (with its fingerprint's first digits where recorded)."""
    words = [
        fields[key] for key in ("machine", "cpu_vendor", "simd", "blas_kernels") if fields.get(key)
    ]
    if fields.get("fingerprint"):
        words.append(f"#{fields['fingerprint'][:8]}")
    return " ".join(words)


def _short(digest: Any) -> str:
    return str(digest)[:12] if digest else "unrecorded"
