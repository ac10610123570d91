"""A griffe extension for the API reference: Sphinx roles in docstrings become links.

The docstrings cross-reference with Sphinx roles (``:class:`World```, ``:mod:`.xflie```,
``:func:`~seminspect.core.rng.make_rng```), which Markdown would print as written. Each role
becomes the name in code font, linked to where the reference documents it: the name is
resolved in the scope of the object whose docstring holds it, as Python would see it there.
The links are optional ones, so a name the reference does not document (a private helper, a
third-party class) stays plain text instead of failing the strict build.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from typing import Any

from griffe import Extension, GriffeLoader, Module, NameResolutionError, Object

ROLE = re.compile(r":(?:class|func|meth|mod|data|attr|exc|obj):`(?P<short>~?)(?P<target>[\w.]+)`")


def documented_objects(obj: Object) -> Iterator[Object]:
    """``obj`` and every object defined inside it (imported names are documented elsewhere)."""
    yield obj
    for member in obj.members.values():
        if not member.is_alias:
            yield from documented_objects(member)  # type: ignore[arg-type]


def resolve(scope: Object, target: str) -> str:
    """The full path of ``target`` (``World``, ``.xflie``, ``RunDirectory.claimed``) as seen
    from ``scope``; a name that cannot be resolved is kept as written."""
    if target.startswith("seminspect."):
        return target
    first, _, rest = target.lstrip(".").partition(".")
    try:
        path = scope.resolve(first)
    except NameResolutionError:
        return target
    return f"{path}.{rest}" if rest else path


def linked_roles(scope: Object, text: str) -> str:
    """``text`` with each Sphinx role replaced by an optional mkdocs-autorefs link."""

    def link(role: re.Match[str]) -> str:
        target = role["target"]
        shown = target.rsplit(".", 1)[-1] if role["short"] else target.lstrip(".")
        identifier = resolve(scope, target)
        return f'<autoref identifier="{identifier}" optional><code>{shown}</code></autoref>'

    return ROLE.sub(link, text)


class SphinxRoles(Extension):
    """Rewrites the roles of every docstring once the package is loaded (names all known)."""

    def on_package(self, *, pkg: Module, loader: GriffeLoader, **kwargs: Any) -> None:
        """Griffe hook: runs once per loaded package, before any docstring is rendered."""
        for obj in documented_objects(pkg):
            if obj.docstring is not None:
                obj.docstring.value = linked_roles(obj, obj.docstring.value)
