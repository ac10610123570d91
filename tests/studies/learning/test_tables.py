"""004 Tables I-III as Markdown, and the published tables pinned to their stored evaluations."""

from __future__ import annotations

from pathlib import Path

import pytest

from seminspect.missions.learning.baselines import OrbitController, RandomController
from seminspect.missions.learning.env import EnvConfig
from seminspect.missions.learning.evaluation import PAPER_TABLE3, evaluate
from seminspect.report.markdown import replace_sections
from seminspect.studies.learning.tables import (
    NEEDS,
    SECTIONS,
    ablation_markdown,
    load_evaluations,
    reproduction_sections,
    table1_evaluations,
    table1_markdown,
)

ROOT = Path(__file__).resolve().parents[3]
SHORT = EnvConfig(episode_seconds=2.0)


@pytest.fixture(scope="module")
def results():
    return {
        name: evaluate(controller, [0, 9], 2, 0, config=SHORT, num_envs=2, policy=name)
        for name, controller in (("orbit", OrbitController()), ("random", RandomController(0)))
    }


def test_table1_puts_the_paper_first_and_every_controller_under_it(results) -> None:
    text = table1_markdown(results)
    lines = text.splitlines()
    assert lines[0] == "| measure | controller | 0 obstacles | 9 obstacles |"
    coverage = [line for line in lines if line.startswith("| coverage %")]
    assert coverage[0] == "| coverage % | 004 (Aerial Gym, GPU) | 92.1 | 74.6 |"
    orbit = results["orbit"]
    expected = (
        f"| coverage % | orbit | {orbit.at(0).coverage_pct:.1f} | {orbit.at(9).coverage_pct:.1f} |"
    )
    assert coverage[1] == expected
    assert len([line for line in lines if line.startswith("| crash %")]) == 3
    assert text.endswith("Episodes per cell: 2.")


def test_an_untrained_variant_says_so(results) -> None:
    ours = {"no GRU": results["random"].at(9), "GRU 128": results["orbit"].at(9), "GRU 512": None}
    text = ablation_markdown(PAPER_TABLE3, ours)
    assert "| coverage % | 004 | 59.8 | 63.6 | 74.6 |" in text
    assert text.count("not trained") == 3  # one per measure


def test_table1_names_its_controllers_by_their_policy_label() -> None:
    stored = load_evaluations(ROOT / "docs" / "data" / "rl")
    rows = table1_evaluations(stored)
    assert list(rows) == ["learned (shipped)", "orbit", "random"]
    assert rows["orbit"] is stored["table1-orbit"]


def test_published_tables_match_their_stored_evaluations() -> None:
    """docs/reproduction.md's 004 tables are what bench/rl_reproduction.py made them."""
    stored = load_evaluations(ROOT / "docs" / "data" / "rl")
    assert {name for names in NEEDS.values() for name in names} <= set(stored)
    doc = (ROOT / "docs" / "reproduction.md").read_text(encoding="utf-8")
    regenerated = replace_sections(doc, reproduction_sections(stored))
    assert regenerated == doc, "rerun: .venv/bin/python bench/rl_reproduction.py --tables-only"
    for section in SECTIONS:
        assert f"<!-- BEGIN table:{section} -->" in doc
    shipped = stored["table1-learned"]
    assert shipped.results[0].episodes == 100
