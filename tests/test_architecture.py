"""The house rules of docs/architecture.md, checked on every import of every module: layers,
siblings, program rooms, cycles, the module map, and the size of a module."""

from __future__ import annotations

import ast
import re
from functools import cache
from pathlib import Path

import networkx as nx
import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "src" / "seminspect"

#: Lower rank = lower layer. A module may import its own subpackage or anything of lower rank;
#: two subpackages of one rank are siblings and never import each other.
RANKS: dict[str, int] = {
    "core": 0,
    "geometry": 1,
    "runs": 1,  # run directories and sweeps: core only, so every program can use them
    "worlds": 2,
    "sensors": 3,
    "robot": 3,
    "platform": 4,
    "perception": 5,
    "mapping": 6,
    "graphs": 7,
    "planning": 8,
    "missions": 9,
    "report": 10,
    "studies": 11,
    "cli": 12,
}
#: Packages whose subpackages are rooms of their own: one per program or paper, never
#: importing each other (what they share lives in a lower layer).
ROOMS = ("graphs", "missions", "studies")
#: The package that holds the programs holds nothing else.
PROGRAMS = "missions"
MAX_MODULE_LINES = 500


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


@cache
def _modules() -> dict[str, Path]:
    return {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def _imports(path: Path) -> list[tuple[int, str]]:
    """``(line, module)`` of every seminspect import in ``path``, lazy and type-only ones
    included: ``from a import b`` names ``a.b`` when ``b`` is a module."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    found: list[tuple[int, str]] = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.extend((node.lineno, alias.name) for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            for alias in node.names:
                submodule = f"{node.module}.{alias.name}"
                found.append((node.lineno, submodule if submodule in _modules() else node.module))
    return [(line, name) for line, name in found if name.split(".")[0] == "seminspect"]


def _part(module: str, depth: int) -> str | None:
    """The subpackage of ``module`` at ``depth`` (1: ``missions``, 2: ``missions.xflie``)."""
    parts = module.split(".")
    return ".".join(parts[1 : depth + 1]) if len(parts) > depth else None


def _ranked() -> list[Path]:
    return [p for name, p in _modules().items() if _part(name, 1) in RANKS]


def _subpackages(depth: int) -> set[str]:
    return {
        ".".join(init.parent.relative_to(PACKAGE).parts)
        for init in PACKAGE.rglob("__init__.py")
        if len(init.parent.relative_to(PACKAGE).parts) == depth
    }


def _relative(path: Path) -> str:
    return str(path.relative_to(PACKAGE))


def test_every_subpackage_has_a_rank() -> None:
    assert _subpackages(1) - {"data"} <= set(RANKS), sorted(_subpackages(1) - set(RANKS))


@pytest.mark.parametrize("path", _ranked(), ids=_relative)
def test_no_module_imports_a_higher_layer_or_a_sibling(path: Path) -> None:
    own = _part(_module_name(path), 1)
    assert own is not None
    bad = []
    for lineno, module in _imports(path):
        target = _part(module, 1)
        if target is None or target == own or target not in RANKS:
            continue
        if RANKS[target] > RANKS[own]:
            bad.append(f"line {lineno}: {own} (rank {RANKS[own]}) imports {module}")
        elif RANKS[target] == RANKS[own]:
            bad.append(f"line {lineno}: {own} imports its sibling {module}")
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("path", _ranked(), ids=_relative)
def test_no_room_imports_another_room(path: Path) -> None:
    own = _part(_module_name(path), 2)
    if _part(_module_name(path), 1) not in ROOMS or own is None or own not in _subpackages(2):
        return
    bad = [
        f"line {lineno}: {own} imports {module}"
        for lineno, module in _imports(path)
        if (target := _part(module, 2)) in _subpackages(2)
        and target != own
        and target.split(".")[0] == own.split(".")[0]
    ]
    assert not bad, "\n".join(bad)


def _import_graph() -> nx.DiGraph:
    graph = nx.DiGraph()
    for name, path in _modules().items():
        graph.add_node(name)
        graph.add_edges_from((name, module) for _, module in _imports(path) if module != name)
    return graph


def test_no_import_cycle() -> None:
    cycles = [sorted(c) for c in nx.strongly_connected_components(_import_graph()) if len(c) > 1]
    assert not cycles, "\n".join(" <-> ".join(c) for c in cycles)


def test_the_cycle_check_finds_a_cycle() -> None:
    graph = _import_graph()
    assert graph.has_edge("seminspect.runs.conduct", "seminspect.runs.directory")
    graph.add_edge("seminspect.runs.directory", "seminspect.runs.conduct")
    assert any(len(c) > 1 for c in nx.strongly_connected_components(graph))


def test_the_programs_package_holds_only_programs() -> None:
    loose = sorted(p.name for p in (PACKAGE / PROGRAMS).glob("*.py") if p.name != "__init__.py")
    assert not loose, f"modules outside a program's room: {loose}"


def _module_map() -> str:
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    return text.split("## Module map", 1)[1].split("\n## ", 1)[0]


def test_the_module_map_names_every_subpackage() -> None:
    named = set(re.findall(r"`([a-z_.]+)/?`", _module_map()))
    packages = (_subpackages(1) | _subpackages(2)) - {"data"}
    assert packages <= named, sorted(packages - named)
    gone = {n for n in named if "." in n and f"seminspect.{n}" not in _modules()}
    assert not gone, f"the map names modules that do not exist: {sorted(gone)}"


@pytest.mark.parametrize(
    "path", list(_modules().values()), ids=lambda p: str(p.relative_to(PACKAGE))
)
def test_no_module_is_longer_than_the_house_allows(path: Path) -> None:
    lines = len(path.read_text(encoding="utf-8").splitlines())
    assert lines <= MAX_MODULE_LINES, f"{lines} lines: split it along its concerns"
