"""The planning study's files: the Markdown beside the paper, the JSON, the figure."""

import json
from pathlib import Path

from seminspect.core.io import read_versioned_json
from seminspect.studies.xflie.tables import study_markdown, write_study
from study_fakes import study


def test_the_markdown_puts_the_papers_numbers_beside_ours() -> None:
    text = study_markdown(study(vp_s=0.06))
    assert "Visit front-bumper-1 in Level-0 of car-2" in text  # ours
    assert "Visit front-glass-1 in Level-1 of truck-16" in text  # the paper's scenario 3 row
    assert "| S3 ours | S3 paper |" in text
    assert "graph edges 97.6% of 41" in text
    assert "| large | 0 | volumetric | 101.0 (118.4) |" in text  # Table 6 beside the paper's
    assert "targets" not in text.split("## Hierarchical")[0]  # judged by bench/, not here


def test_the_study_is_written_as_markdown_json_and_a_figure(tmp_path: Path) -> None:
    written = write_study(study(), tmp_path)
    assert written["figure"].read_bytes()[:4] == b"\x89PNG"
    document = read_versioned_json(written["json"], "seminspect.planning-study", [1])
    first = document["table5"][0]["queries"][0]
    assert first["vp"][2]["time_s"] is None and first["vp"][2]["error"] == "no route"
    assert document["paper_table6"]["large"]["hierarchical"] == [52.10, 573.40, 0.24]
    assert len(document["scaling"]) == 3 and "targets" not in document
    json.loads(written["json"].read_text())  # strict JSON: no NaN
    assert written["markdown"].read_text().startswith("# Planning study")
