"""Each subpackage's public face: ``__all__`` names what it exports, and the README uses it."""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "src" / "seminspect"
SUBPACKAGES = sorted(
    ".".join(("seminspect", *init.parent.relative_to(PACKAGE).parts))
    for init in PACKAGE.rglob("__init__.py")
    if init.parent != PACKAGE and init.parent.name != "cli"
)


@pytest.mark.parametrize("name", SUBPACKAGES)
def test_every_subpackage_exports_its_public_names(name: str) -> None:
    module = importlib.import_module(name)
    exported = module.__all__
    assert exported and len(set(exported)) == len(exported)
    for public in exported:
        assert getattr(module, public) is not None, public


def test_the_package_ships_its_type_information() -> None:
    assert (PACKAGE / "py.typed").exists()


def test_the_readme_python_example_imports_only_public_names() -> None:
    readme = (ROOT / "README.md").read_text()
    example = readme.split("```python", 1)[1].split("```", 1)[0]
    imports = re.findall(r"from (seminspect[\w.]*) import ([\w, ]+)", example)
    assert imports
    for module_name, names in imports:
        module = importlib.import_module(module_name)
        for name in (n.strip() for n in names.split(",")):
            assert name in module.__all__, f"{module_name}.{name} is not public"
