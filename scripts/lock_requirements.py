"""Write ``requirements.lock``: the exact versions of every package seminspect and its extras need.

The lock is read from the virtual environment that runs this script (the one that produced the
published figures), but only for the packages that seminspect's installed metadata (that is,
``pyproject.toml``) asks for, with every extra, and what they need in turn: whatever else happens
to be installed there stays out. The Makefile
installs with ``-c requirements.lock``, so a fresh clone gets these versions while library users
keep the ranges of ``pyproject.toml``.

Run: ``make lock`` (or ``.venv/bin/python scripts/lock_requirements.py [--out requirements.lock]``).
"""

from __future__ import annotations

import argparse
import platform
import sys
from importlib import metadata
from pathlib import Path

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name
from packaging.version import Version

ROOT = Path(__file__).resolve().parents[1]


def project_with_every_extra() -> Requirement:
    """seminspect as installed (its metadata is pyproject.toml's), with all its extras."""
    extras = metadata.distribution("seminspect").metadata.get_all("Provides-Extra") or []
    return Requirement(f"seminspect[{','.join(extras)}]")


def applies(requirement: Requirement, extras: set[str]) -> bool:
    """Whether a requirement holds on this interpreter, for a package installed with ``extras``."""
    if requirement.marker is None:
        return True
    return any(requirement.marker.evaluate({"extra": extra}) for extra in extras or {""})


def closure(roots: list[Requirement]) -> dict[str, str]:
    """Installed version of every package the roots need, transitively, by canonical name."""
    pinned: dict[str, str] = {}
    seen: set[tuple[str, frozenset[str]]] = set()
    pending = [(r, {""}) for r in roots]
    while pending:
        requirement, parent_extras = pending.pop()
        if not applies(requirement, parent_extras):
            continue
        name = canonicalize_name(requirement.name)
        key = (name, frozenset(requirement.extras))
        if key in seen:
            continue
        seen.add(key)
        try:
            dist = metadata.distribution(requirement.name)
        except metadata.PackageNotFoundError:
            sys.exit(f"{requirement.name} is required but not installed; install '.[test]' first")
        pinned[name] = dist.version
        extras = set(requirement.extras) | {""}
        pending += [(Requirement(text), extras) for text in dist.requires or []]
    return pinned


def lock_line(name: str, version: str) -> str:
    """``name==version``; a local build label (torch's ``+cpu``) is dropped, since ``==2.13.0``
    also matches ``2.13.0+cpu`` and the label is the choice of an index, not of a version."""
    return f"{name}=={Version(version).public}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=ROOT / "requirements.lock")
    args = parser.parse_args()
    pinned = closure([project_with_every_extra()])
    pinned.pop("seminspect", None)
    header = [
        "# Exact versions behind the published figures (every extra included).",
        f"# Python {platform.python_version()} on {platform.system()} {platform.machine()}.",
        "# Regenerate with `make lock`; installs use it as constraints:",
        "#   pip install -c requirements.lock -e '.[test]'",
    ]
    lines = [lock_line(name, pinned[name]) for name in sorted(pinned)]
    args.out.write_text("\n".join([*header, *lines]) + "\n", encoding="utf-8")
    print(f"wrote {len(lines)} pins to {args.out}")


if __name__ == "__main__":
    main()
