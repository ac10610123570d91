"""004 Tables I-III as Markdown, and the published tables pinned to their stored evaluations."""

from __future__ import annotations

from pathlib import Path

import pytest

from seminspect.core.errors import FileFormatError
from seminspect.missions.learning.baselines import OrbitController, RandomController
from seminspect.missions.learning.env import EnvConfig
from seminspect.missions.learning.evaluation import PAPER_TABLE3, REGENERATE, evaluate
from seminspect.report.markdown import replace_sections
from seminspect.studies.learning.tables import (
    NEEDS,
    SECTIONS,
    ablation_markdown,
    generalisation_markdown,
    load_evaluations,
    policies_markdown,
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


def _interval(value: float, interval: tuple[float, float]) -> str:
    return f"{value:.1f} [{interval[0]:.1f}-{interval[1]:.1f}]"


def test_table1_puts_the_paper_first_and_every_controller_under_it(results) -> None:
    text = table1_markdown(results)
    lines = text.splitlines()
    assert lines[0] == "| measure | controller | 0 obstacles | 9 obstacles |"
    lenient = [line for line in lines if line.startswith("| coverage % (lenient)")]
    assert lenient[0] == "| coverage % (lenient) | 004 (Aerial Gym, GPU) | 92.1 | 74.6 |"
    orbit = results["orbit"]
    a, b = orbit.at(0), orbit.at(9)
    assert (
        lenient[1]
        == f"| coverage % (lenient) | orbit | {a.coverage_pct:.1f} | {b.coverage_pct:.1f} |"
    )
    strict = [line for line in lines if line.startswith("| strict coverage %")]
    assert strict[0] == "| strict coverage % | 004 (Aerial Gym, GPU) | 92.1 | 74.6 |"
    cells = [_interval(r.strict_coverage_pct, r.strict_coverage_ci) for r in (a, b)]
    assert strict[1] == f"| strict coverage % | orbit | {' | '.join(cells)} |"
    crash = [line for line in lines if line.startswith("| crash %")]
    assert crash[0] == "| crash % | 004 (Aerial Gym, GPU) | 0.0 | 1.2 |"
    assert crash[1].endswith(f"| {_interval(b.crash_pct, b.crash_ci)} |")
    scores = [line for line in lines if line.startswith("| distance score")]
    assert len(scores) == 2  # 004 gives none: only our two controllers
    assert (
        scores[0] == f"| distance score | orbit | {a.distance_score:.2f} | {b.distance_score:.2f} |"
    )
    assert text.endswith("Episodes per cell: 2.")


def test_an_untrained_variant_says_so(results) -> None:
    ours = {"no GRU": results["random"].at(9), "GRU 128": results["orbit"].at(9), "GRU 512": None}
    text = ablation_markdown(PAPER_TABLE3, ours)
    assert "| coverage % (lenient) | 004 | 59.8 | 63.6 | 74.6 |" in text
    assert "| crash % | 004 | 3.6 | 1.1 | 1.2 |" in text
    assert text.count("not trained") == 5  # one per measure


def test_generalisation_marks_the_shapes_a_policy_never_trained_on(results) -> None:
    box = evaluate(
        OrbitController(), [9], 2, 0, config=SHORT.model_copy(update={"target_shapes": ("box",)}),
        num_envs=2, policy="orbit",
    )  # fmt: skip
    cylinder = results["orbit"]
    table = {"cylinders only": {"cylinder": cylinder, "box": box}, "boxes": {"box": box}}
    text = generalisation_markdown(table, {"cylinders only": ["cylinder"], "boxes": ["box"]})
    lines = text.splitlines()
    assert lines[0] == "| measure | policy | cylinder | box |"
    row = cylinder.at(9)
    strict = _interval(row.strict_coverage_pct, row.strict_coverage_ci)
    on_box = _interval(box.at(9).strict_coverage_pct, box.at(9).strict_coverage_ci)
    assert lines[2] == f"| strict coverage % | cylinders only | {strict} | {on_box} (unseen) |"
    assert lines[3] == f"| strict coverage % | boxes | - | {on_box} |"
    assert sum(line.startswith("| crash % |") for line in lines) == 2
    assert text.count("(unseen)") == 2  # the box column of the cylinder policy, per measure
    assert text.endswith("9 obstacles; episodes per cell: 2.")


def test_policies_side_by_side_give_every_measure_at_one_obstacle_count(results) -> None:
    text = policies_markdown({"orbit": results["orbit"], "random": results["random"]}, 9)
    lines = text.splitlines()
    assert lines[0] == (
        "| policy | coverage % (lenient) | strict coverage % | distance score | crash % "
        "| timeout % |"
    )
    assert lines[2] == "| 004 (Aerial Gym, GPU) | 74.6 | 74.6 | - | 1.2 | 98.8 |"
    row = results["random"].at(9)
    assert lines[4] == (
        f"| random | {row.coverage_pct:.1f} | "
        f"{_interval(row.strict_coverage_pct, row.strict_coverage_ci)} | "
        f"{row.distance_score:.2f} | {_interval(row.crash_pct, row.crash_ci)} | "
        f"{row.timeout_pct:.1f} |"
    )
    assert text.endswith("9 obstacles; episodes per cell: 2.")


def _fresh_store(results, directory: Path) -> Path:
    """Small evaluations under the stored files' names (the stored ones are regenerated)."""
    labels = {
        "table1-learned": "learned (shipped)", "table1-orbit": "orbit", "table1-random": "random",
        "ablation-no-svs": "no SVS map", "ablation-no-gru": "no GRU",
    }  # fmt: skip
    for name, label in labels.items():
        source = results["random" if name == "table1-random" else "orbit"]
        source.model_copy(update={"policy": label}).to_json(directory / f"{name}.json")
    return directory


def test_table1_names_its_controllers_by_their_policy_label(results, tmp_path) -> None:
    stored = load_evaluations(_fresh_store(results, tmp_path))
    rows = table1_evaluations(stored)
    assert list(rows) == ["learned (shipped)", "orbit", "random"]
    assert rows["orbit"] is stored["table1-orbit"]
    tables = {"rl-table1", "rl-table2", "rl-table3"}  # the shapes need their own evaluations
    sections = reproduction_sections(stored, tables)
    assert set(sections) == tables
    assert "| crash % | 004 | 1.0 | 1.2 |" in sections["rl-table2"]
    assert sections["rl-table3"].count("not trained") == 5  # no GRU 512 of ours


def test_published_tables_match_their_stored_evaluations() -> None:
    """docs/reproduction.md's 004 tables are what bench/rl_reproduction.py made them."""
    try:
        stored = load_evaluations(ROOT / "docs" / "data" / "rl")
    except FileFormatError as error:
        if "version-1" not in str(error):
            raise
        pytest.skip(f"docs/data/rl/*.json are version 1 (lenient only): rerun {REGENERATE}")
    assert {name for names in NEEDS.values() for name in names} <= set(stored)
    doc = (ROOT / "docs" / "reproduction.md").read_text(encoding="utf-8")
    regenerated = replace_sections(doc, reproduction_sections(stored))
    assert regenerated == doc, "rerun: .venv/bin/python bench/rl_reproduction.py --tables-only"
    for section in SECTIONS:
        assert f"<!-- BEGIN table:{section} -->" in doc
    shipped = stored["table1-learned"]
    assert shipped.results[0].episodes == 100
    assert shipped.checkpoint_sha256 is not None


def test_the_shapes_section_takes_each_policys_training_shapes_from_its_evaluation() -> None:
    class Trained(RandomController):
        env_config = EnvConfig.legacy()  # cylinders only, as policy v1

    learned, orbit = Trained(0), OrbitController()
    stored = {}
    for stem, controller, label in (
        ("learned", learned, "learned (shipped)"),
        ("orbit", orbit, "orbit"),
    ):
        for shape in ("cylinder", "box", "sphere", "t-pipe"):
            config = SHORT.model_copy(update={"target_shapes": (shape,)})
            result = evaluate(controller, [9], 1, 0, config=config, num_envs=1, policy=label)
            name = f"table1-{stem}" if shape == "cylinder" else f"shape-{stem}-{shape}"
            stored[name] = result
    text = reproduction_sections(stored, {"rl-shapes"})["rl-shapes"]
    learned_rows = [line for line in text.splitlines() if "| learned (shipped) |" in line]
    assert len(learned_rows) == 2  # strict coverage and crash
    for row in learned_rows:
        cells = row.split(" | ")[2:]
        assert "(unseen)" not in cells[0] and all("(unseen)" in c for c in cells[1:])
    assert "(unseen)" not in "".join(line for line in text.splitlines() if "| orbit |" in line)
