"""The API reference's pages, made at build time from the package tree (a mkdocs hook).

Each subpackage of seminspect gets one page listing, with mkdocstrings' ``:::`` directive, its
docstring and then every public module, with its nested subpackages as sections of the same
page. The pages are read from ``src/seminspect`` at each build, so a module or subpackage that
is added, moved or removed is documented where it now lives without anyone editing a list.
Private modules (``_common``) and ``__main__`` stay out, and so do folders that are not
packages (data).
"""

from __future__ import annotations

from pathlib import Path

from mkdocs.config.defaults import MkDocsConfig
from mkdocs.structure.files import File, Files

PACKAGE_DIR = Path(__file__).resolve().parents[2] / "src" / "seminspect"


def is_package(folder: Path) -> bool:
    """Whether a folder is a regular package (data folders and caches are not)."""
    return (folder / "__init__.py").is_file()


def subpackages(package: Path) -> list[Path]:
    """The public packages directly inside ``package``, by name."""
    folders = (p for p in package.iterdir() if is_package(p) and not p.name.startswith("_"))
    return sorted(folders)


def modules(package: Path) -> list[Path]:
    """The public plain modules directly inside ``package``, by name."""
    return sorted(p for p in package.glob("*.py") if not p.name.startswith("_"))


def dotted_name(path: Path) -> str:
    """``.../seminspect/core/io.py`` -> ``seminspect.core.io``; a package is named by its
    folder, and the name climbs as far as the folders are packages."""
    parts = [] if path.is_dir() or path.name == "__init__.py" else [path.stem]
    folder = path if path.is_dir() else path.parent
    while is_package(folder):
        parts.insert(0, folder.name)
        folder = folder.parent
    return ".".join(parts)


def directive(name: str, heading_level: int, *, package: bool) -> str:
    """A mkdocstrings block for one object. A package shows its docstring only: the names it
    re-exports are documented in the modules that define them."""
    lines = [f"::: {name}", "    options:", f"      heading_level: {heading_level}"]
    if package:
        lines.append("      members: false")
    return "\n".join(lines)


def package_blocks(package: Path, heading_level: int) -> list[str]:
    """A package's section: its docstring, then its modules and its subpackages' sections,
    both one heading level down."""
    blocks = [directive(dotted_name(package), heading_level, package=True)]
    inner = heading_level + 1
    blocks += [directive(dotted_name(m), inner, package=False) for m in modules(package)]
    for child in subpackages(package):
        blocks += package_blocks(child, inner)
    return blocks


def page_markdown(package: Path) -> str:
    """One subpackage's page: the package's own heading is the page's only level-1 one, so
    that the navigation lists its modules under it; the title is set for the navigation."""
    front_matter = f"---\ntitle: {dotted_name(package)}\n---"
    return "\n\n".join([front_matter, *package_blocks(package, 1)]) + "\n"


def api_pages(package_dir: Path = PACKAGE_DIR) -> dict[str, str]:
    """The reference's generated pages, ``{file name: markdown}``: one per subpackage."""
    return {f"{p.name}.md": page_markdown(p) for p in subpackages(package_dir)}


def on_files(files: Files, config: MkDocsConfig) -> Files:
    """mkdocs hook: add the generated pages beside the hand-written ones of ``docs_dir``."""
    for name, markdown in api_pages().items():
        files.append(File.generated(config, name, content=markdown))
    return files
