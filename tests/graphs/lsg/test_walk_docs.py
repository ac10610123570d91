"""The docs' "Walking a graph from Python" runs as written: every ``pycon`` block of that
section of docs/scene-graph.md is executed with doctest, in order, and its output compared."""

from __future__ import annotations

import doctest
import re
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[3] / "docs" / "scene-graph.md"
SECTION = "## Walking a graph from Python"


def section_blocks(markdown: str, heading: str) -> list[str]:
    """The ``pycon`` code blocks between ``heading`` and the next ``## `` heading."""
    start = markdown.index(heading) + len(heading)
    end = markdown.find("\n## ", start)
    body = markdown[start : end if end >= 0 else None]
    return re.findall(r"^```pycon\n(.*?)^```$", body, flags=re.DOTALL | re.MULTILINE)


def test_the_section_has_examples_of_every_step() -> None:
    code = "\n".join(section_blocks(DOCS.read_text(encoding="utf-8"), SECTION))
    for step in ("load_graph(", ".levels", ".poses", ".features", ".pose is", "export_csv("):
        assert step in code, step


def test_the_walk_in_the_docs_runs_and_prints_what_it_says(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)  # the example writes its CSV tables here
    blocks = section_blocks(DOCS.read_text(encoding="utf-8"), SECTION)
    assert len(blocks) >= 2
    test = doctest.DocTestParser().get_doctest("\n".join(blocks), {}, SECTION, str(DOCS), 0)
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    report: list[str] = []
    runner.run(test, out=report.append)
    assert runner.failures == 0, "".join(report)
    assert test.examples and runner.tries == len(test.examples)
    assert (tmp_path / "example_csv" / "poses.csv").is_file()
