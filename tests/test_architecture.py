"""The layering rule of docs/architecture.md, checked on every module's imports."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "seminspect"

#: Lower rank = lower layer. A module may import its own subpackage or anything of lower rank.
RANKS: dict[str, int] = {
    "core": 0,
    "geometry": 1,
    "worlds": 2,
    "sensors": 3,
    "robot": 3,
    "perception": 4,
    "mapping": 5,
    "graphs": 6,
    "planning": 7,
    "missions": 8,
    "learning": 8,
    "report": 9,
    "studies": 10,
    "cli": 11,
}


def _subpackage(module: str) -> str | None:
    parts = module.split(".")
    if parts[0] != "seminspect" or len(parts) < 2:
        return None
    return parts[1]


def _imports(path: Path) -> list[tuple[int, str]]:
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    found: list[tuple[int, str]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.extend((node.lineno, alias.name) for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.append((node.lineno, node.module))
    return found


def _modules() -> list[Path]:
    return sorted(p for p in PACKAGE.rglob("*.py") if p.relative_to(PACKAGE).parts[0] in RANKS)


def test_every_subpackage_has_a_rank() -> None:
    subpackages = {p.name for p in PACKAGE.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    assert subpackages - {"data"} <= set(RANKS), sorted(subpackages - set(RANKS))


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_no_lower_layer_imports_a_higher_one(path: Path) -> None:
    own = path.relative_to(PACKAGE).parts[0]
    bad = []
    for lineno, module in _imports(path):
        target = _subpackage(module)
        if target is None or target == own or target not in RANKS:
            continue
        if RANKS[target] > RANKS[own]:
            bad.append(f"line {lineno}: {own} (rank {RANKS[own]}) imports {module}")
    assert not bad, "\n".join(bad)
