"""Generated sections inside hand-written Markdown: tables that a command rewrites in place.

A section is the text between ``<!-- BEGIN table:NAME -->`` and ``<!-- END table:NAME -->``
lines; everything outside the markers is left as written, so prose and the paper's own rows
stay hand-edited while measured tables are regenerated (``bench/reproduction.py``). Tables
over seeds give continuous figures as mean ± standard deviation (:func:`mean_sd`) and counts as
median and range (:func:`median_range`).
"""

from __future__ import annotations

import math
import os
import re
import statistics
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path

from seminspect.core.errors import FileFormatError
from seminspect.core.io import atomic_write_text

_MARKER = re.compile(r"^<!-- (BEGIN|END) table:([\w.-]+) -->$", re.MULTILINE)


def section_names(text: str) -> list[str]:
    """The names of the generated sections of ``text``, in order; malformed markers (an END
    without its BEGIN, a section opened twice or never closed) raise ``FileFormatError``."""
    names: list[str] = []
    open_name: str | None = None
    for match in _MARKER.finditer(text):
        kind, name = match.groups()
        if kind == "BEGIN":
            if open_name is not None:
                raise FileFormatError(f"section {open_name!r} is not closed before {name!r}")
            if name in names:
                raise FileFormatError(f"section {name!r} appears twice")
            open_name = name
        elif name != open_name:
            raise FileFormatError(f"END of section {name!r} without its BEGIN")
        else:
            names.append(name)
            open_name = None
    if open_name is not None:
        raise FileFormatError(f"section {open_name!r} is never closed")
    return names


def replace_sections(text: str, sections: Mapping[str, str]) -> str:
    """``text`` with the body of each named section replaced; sections not named are kept."""
    unknown = sorted(set(sections) - set(section_names(text)))
    if unknown:
        raise FileFormatError(f"no section named {', '.join(unknown)} in the document")
    for name, body in sections.items():
        text = _section(name).sub(_verbatim(body.strip("\n") + "\n"), text, count=1)
    return text


def section_body(text: str, name: str) -> str:
    """The body of section ``name`` of ``text``, without its markers."""
    if name not in section_names(text):
        raise FileFormatError(f"no section named {name} in the document")
    match = _section(name).search(text)
    assert match is not None  # section_names found both markers
    return match.group(2)


def _section(name: str) -> re.Pattern[str]:
    """A section's BEGIN line, body and END line as groups 1-3."""
    key = re.escape(name)
    return re.compile(
        rf"(^<!-- BEGIN table:{key} -->\n)(.*?)(^<!-- END table:{key} -->$)",
        re.MULTILINE | re.DOTALL,
    )


def _verbatim(lines: str) -> Callable[[re.Match[str]], str]:
    """A replacement function: the body is written as given, backslashes and all."""
    return lambda match: match.group(1) + lines + match.group(3)


def rewrite_sections(path: str | os.PathLike[str], sections: Mapping[str, str]) -> Path:
    """Replace the named sections of the Markdown file at ``path`` (atomically)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise FileFormatError(f"{path}: cannot read ({exc.strerror})") from exc
    try:
        return atomic_write_text(path, replace_sections(text, sections))
    except FileFormatError as exc:
        raise FileFormatError(f"{path}: {exc}") from exc


# --- cells of tables over seeds ---------------------------------------------------------------
def _finite(values: Iterable[float | None]) -> list[float]:
    return [float(v) for v in values if v is not None and math.isfinite(v)]


def mean_sd(values: Iterable[float | None], digits: int) -> str:
    """``mean ± sample standard deviation`` of the finite values, each to ``digits`` decimals
    (the mean alone for one value, ``-`` for none): a continuous figure over seeds."""
    finite = _finite(values)
    if not finite:
        return "-"
    mean = f"{statistics.fmean(finite):.{digits}f}"
    return mean if len(finite) == 1 else f"{mean} ± {statistics.stdev(finite):.{digits}f}"


def median_range(values: Iterable[float | None], digits: int = 0) -> str:
    """``median [min-max]`` of the finite values (the median alone where all agree, ``-`` for
    none): a count over seeds."""
    finite = _finite(values)
    if not finite:
        return "-"
    low, middle, high = (
        f"{v:.{digits}f}" for v in (min(finite), statistics.median(finite), max(finite))
    )
    return middle if low == high else f"{middle} [{low}-{high}]"


def seeds_cell(seeds: Sequence[int]) -> str:
    """How a table names its seeds: ``0-4`` for a run of three or more, else ``0, 2``."""
    seeds = sorted(seeds)
    contiguous = seeds == list(range(seeds[0], seeds[-1] + 1))
    return (
        f"{seeds[0]}-{seeds[-1]}" if contiguous and len(seeds) > 2 else ", ".join(map(str, seeds))
    )
