import pytest

from seminspect.core.errors import FileFormatError
from seminspect.report.markdown import (
    mean_sd,
    median_range,
    replace_sections,
    rewrite_sections,
    section_body,
    section_names,
    seeds_cell,
)

DOC = """# Results

Prose that stays.

<!-- BEGIN table:t3 -->
| a | b |
|---|---|
| 1 | 2 |
<!-- END table:t3 -->

More prose.
<!-- BEGIN table:t6 -->
old
<!-- END table:t6 -->
"""


def test_only_the_named_sections_are_rewritten() -> None:
    new = replace_sections(DOC, {"t3": "| a | b |\n|---|---|\n| 3 | 4 |\n"})
    assert "| 3 | 4 |" in new and "| 1 | 2 |" not in new
    assert "Prose that stays." in new and "More prose." in new and "\nold\n" in new
    assert section_names(new) == ["t3", "t6"]
    assert replace_sections(new, {"t3": "| a | b |\n|---|---|\n| 1 | 2 |"}) == DOC


def test_a_body_with_regex_escapes_is_written_verbatim() -> None:
    body = r"path \1 and \g<0> stay as written"
    assert body + "\n<!-- END table:t6 -->" in replace_sections(DOC, {"t6": body})


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("<!-- BEGIN table:x -->\n", "'x' is never closed"),
        ("<!-- END table:x -->\n", "END of section 'x' without its BEGIN"),
        ("<!-- BEGIN table:x -->\n<!-- BEGIN table:y -->\n", "'x' is not closed before 'y'"),
        (DOC + DOC, "'t3' appears twice"),
    ],
)
def test_malformed_markers_are_refused(text: str, message: str) -> None:
    with pytest.raises(FileFormatError, match=message):
        section_names(text)


def test_an_unknown_section_is_refused_and_the_file_kept(tmp_path) -> None:
    doc = tmp_path / "doc.md"
    doc.write_text(DOC, encoding="utf-8")
    with pytest.raises(FileFormatError, match="no section named t9"):
        rewrite_sections(doc, {"t9": "x"})
    assert doc.read_text(encoding="utf-8") == DOC
    rewrite_sections(doc, {"t6": "new"})
    assert "\nnew\n<!-- END table:t6 -->" in doc.read_text(encoding="utf-8")
    with pytest.raises(FileFormatError, match="cannot read"):
        rewrite_sections(tmp_path / "missing.md", {"t6": "x"})


def test_a_sections_body_is_read_back_without_its_markers() -> None:
    assert section_body(DOC, "t3") == "| a | b |\n|---|---|\n| 1 | 2 |\n"
    assert section_body(DOC, "t6") == "old\n"
    with pytest.raises(FileFormatError, match="no section named t5"):
        section_body(DOC, "t5")


def test_a_figure_over_seeds_is_mean_and_spread_and_a_count_median_and_range() -> None:
    assert mean_sd([0.063, 0.067, 0.066], 3) == "0.065 ± 0.002"
    assert mean_sd([0.07], 3) == "0.070"  # one run has no spread
    assert mean_sd([None, float("nan")], 1) == "-"
    assert median_range([150, 155, 167, 152]) == "154 [150-167]"
    assert median_range([6, 6, 6]) == "6"
    assert median_range([]) == "-"


def test_seeds_are_named_as_a_run_or_one_by_one() -> None:
    assert seeds_cell([4, 0, 1, 2, 3]) == "0-4"
    assert seeds_cell([0, 2, 3]) == "0, 2, 3"
    assert seeds_cell([1, 2]) == "1, 2"  # two seeds are listed, not a run
    assert seeds_cell([3]) == "3"
