"""The API reference's generation (docs/hooks/), checked without building it: every subpackage
of seminspect has its place, every page names modules that exist, and Sphinx roles become links
to the objects they name."""

from __future__ import annotations

import importlib.util
import pkgutil
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import griffe
import yaml

ROOT = Path(__file__).resolve().parents[1]
PACKAGE_DIR = ROOT / "src" / "seminspect"
HOOKS = ROOT / "docs" / "hooks"
HOOK = HOOKS / "api_pages.py"


def load_hook(name: str = "api_pages") -> ModuleType:
    spec = importlib.util.spec_from_file_location(name, HOOKS / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def public_modules(folder: Path, prefix: str) -> Iterator[tuple[str, bool]]:
    """``(dotted name, is a package)`` of every public module under ``folder``, found the way
    Python's import system sees the tree (independently of the hook's own walk)."""
    for info in pkgutil.iter_modules([str(folder)], prefix):
        if info.name.rsplit(".", 1)[-1].startswith("_"):
            continue
        yield info.name, info.ispkg
        if info.ispkg:
            yield from public_modules(folder / info.name.rsplit(".", 1)[-1], f"{info.name}.")


def documented(markdown: str) -> list[str]:
    """The targets of a page's ``:::`` lines."""
    return [line.removeprefix("::: ") for line in markdown.splitlines() if line.startswith("::: ")]


def source_exists(name: str) -> bool:
    parts = name.split(".")
    path = PACKAGE_DIR.parent.joinpath(*parts)
    return path.with_suffix(".py").is_file() or (path / "__init__.py").is_file()


PAGES = load_hook().api_pages()
LISTED = [name for page in PAGES.values() for name in documented(page)]


def test_the_build_uses_this_hook() -> None:
    config = yaml.safe_load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"))
    assert [ROOT / hook for hook in config["hooks"]] == [HOOK]


def test_every_top_level_subpackage_has_its_own_page() -> None:
    top = {name for name, is_pkg in public_modules(PACKAGE_DIR, "seminspect.") if is_pkg}
    top = {name for name in top if name.count(".") == 1}
    assert {"seminspect.core", "seminspect.runs", "seminspect.missions"} <= top
    assert {f"seminspect.{page.removesuffix('.md')}" for page in PAGES} == top
    for page, markdown in PAGES.items():
        name = f"seminspect.{page.removesuffix('.md')}"
        assert markdown.startswith(f"---\ntitle: {name}\n---\n\n::: {name}\n")


def test_every_public_module_and_subpackage_is_listed_once() -> None:
    expected = {name for name, _ in public_modules(PACKAGE_DIR, "seminspect.")}
    assert "seminspect.missions.learning.policy" in expected  # imports torch at module level
    assert len(LISTED) == len(set(LISTED))
    assert set(LISTED) == expected


def test_no_page_lists_a_module_that_does_not_exist() -> None:
    assert [name for name in LISTED if not source_exists(name)] == []


def test_a_new_subpackage_gets_a_page_without_editing_any_list(tmp_path: Path) -> None:
    package = tmp_path / "pkg"
    for folder in (package, package / "alpha", package / "alpha" / "deep"):
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "__init__.py").write_text('"""A package."""\n')
    (package / "alpha" / "mod.py").write_text('"""A module."""\n')
    (package / "alpha" / "_private.py").write_text("")
    (package / "alpha" / "deep" / "leaf.py").write_text("")
    (package / "data").mkdir()  # a data folder, not a package
    (package / "data" / "helper.py").write_text("")

    pages = load_hook().api_pages(package)

    assert list(pages) == ["alpha.md"]
    assert documented(pages["alpha.md"]) == [
        "pkg.alpha",
        "pkg.alpha.mod",
        "pkg.alpha.deep",
        "pkg.alpha.deep.leaf",
    ]


def test_sphinx_roles_link_to_the_object_they_name_in_their_scope() -> None:
    sphinx_roles = load_hook("sphinx_roles")
    files = {
        "__init__.py": "",
        "a.py": "def make(): ...\nclass Thing:\n    def go(self): ...\n",
        "b.py": (
            '"""Uses :class:`Thing`, :mod:`.a`, :func:`~pkg.a.make`, :meth:`Thing.go` and'
            ' :class:`Missing`; ``code`` stays."""\n'
            "from pkg.a import Thing\n"
        ),
    }
    extensions = griffe.load_extensions(sphinx_roles.SphinxRoles)
    with griffe.temporary_visited_package("pkg", files, extensions=extensions) as package:
        docstring = package["b"].docstring.value

    def link(identifier: str, shown: str) -> str:
        return f'<autoref identifier="{identifier}" optional><code>{shown}</code></autoref>'

    assert docstring == (
        f"Uses {link('pkg.a.Thing', 'Thing')}, {link('pkg.a', 'a')}, {link('pkg.a.make', 'make')},"
        f" {link('pkg.a.Thing.go', 'Thing.go')} and {link('Missing', 'Missing')}; ``code`` stays."
    )
