"""Markdown tables of learned-inspection evaluations beside 004 Tables I-III.

Each table puts the paper's rows first and ours under them, one measure (coverage, crash,
timeout) per block, so a reader compares numbers in the same column. Percentages have one
decimal, as in the paper.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

from seminspect.missions.learning.evaluation import (
    PAPER_TABLE1,
    PAPER_TABLE2,
    PAPER_TABLE3,
    EvaluationResult,
    ObstacleResult,
)

#: The sections of docs/reproduction.md, and the stored evaluations (file stems) each needs.
SECTIONS = ("rl-table1", "rl-table2", "rl-table3")
NEEDS = {
    "rl-table1": ("table1-learned", "table1-orbit", "table1-random"),
    "rl-table2": ("table1-learned", "ablation-no-svs"),
    "rl-table3": ("table1-learned", "ablation-no-gru"),
}
#: 004 Tables II and III are measured in rooms with nine obstacles.
ABLATION_OBSTACLES = 9
MEASURES = (("coverage %", "coverage_pct"), ("crash %", "crash_pct"), ("timeout %", "timeout_pct"))


def _cells(values: Sequence[float | str | None]) -> str:
    """Table cells: one decimal for numbers, text as given, "-" for a missing paper value."""
    return " | ".join("-" if v is None else v if isinstance(v, str) else f"{v:.1f}" for v in values)


def table1_markdown(results: Mapping[str, EvaluationResult]) -> str:
    """004 Table I beside ours: one column per obstacle count, one row per controller.

    ``results`` maps a row label (e.g. "learned (shipped)", "orbit") to its evaluation; every
    evaluation must cover the same obstacle counts.
    """
    counts = [row.obstacles for row in next(iter(results.values())).results]
    lines = [
        "| measure | controller | " + " | ".join(f"{k} obstacles" for k in counts) + " |",
        "|---|---|" + "---:|" * len(counts),
    ]
    for index, (label, field) in enumerate(MEASURES):
        paper = [PAPER_TABLE1[k][index] if k in PAPER_TABLE1 else None for k in counts]
        lines.append(f"| {label} | 004 (Aerial Gym, GPU) | {_cells(paper)} |")
        for name, result in results.items():
            ours = [getattr(result.at(k), field) for k in counts]
            lines.append(f"| {label} | {name} | {_cells(ours)} |")
    episodes = {row.episodes for result in results.values() for row in result.results}
    lines.append("")
    lines.append(f"Episodes per cell: {', '.join(str(n) for n in sorted(episodes))}.")
    return "\n".join(lines)


def ablation_markdown(
    paper: Mapping[str, tuple[float, float, float]],
    ours: Mapping[str, ObstacleResult | None],
) -> str:
    """004 Table II or III beside ours: one column per network variant.

    ``paper`` and ``ours`` share their keys (the column headers); a variant we did not train
    is None and shows as "not trained".
    """
    columns = list(paper)
    lines = [
        "| measure | source | " + " | ".join(columns) + " |",
        "|---|---|" + "---:|" * len(columns),
    ]
    for index, (label, field) in enumerate(MEASURES):
        lines.append(f"| {label} | 004 | {_cells([paper[c][index] for c in columns])} |")
        row = [_measure(ours.get(c), field) for c in columns]
        lines.append(f"| {label} | ours | {_cells(row)} |")
    episodes = sorted({r.episodes for r in ours.values() if r is not None})
    lines.append("")
    lines.append(f"Episodes per cell: {', '.join(str(n) for n in episodes)}.")
    return "\n".join(lines)


def _measure(result: ObstacleResult | None, field: str) -> float | str:
    return "not trained" if result is None else float(getattr(result, field))


def load_evaluations(directory: Path) -> dict[str, EvaluationResult]:
    """Every stored evaluation of a directory, by file stem."""
    return {p.stem: EvaluationResult.from_json(p) for p in sorted(directory.glob("*.json"))}


def table1_evaluations(results: Mapping[str, EvaluationResult]) -> dict[str, EvaluationResult]:
    """The controllers of Table I (and of its coverage figure), by their policy label."""
    return {results[n].policy: results[n] for n in NEEDS["rl-table1"]}


def reproduction_sections(
    results: Mapping[str, EvaluationResult], wanted: set[str] | None = None
) -> dict[str, str]:
    """The bodies of the wanted docs/reproduction.md sections from the stored evaluations."""
    wanted = set(SECTIONS) if wanted is None else wanted
    sections: dict[str, str] = {}
    if "rl-table1" in wanted:
        sections["rl-table1"] = table1_markdown(table1_evaluations(results))
    shipped = results["table1-learned"].at(ABLATION_OBSTACLES)
    if "rl-table2" in wanted:
        no_svs = results["ablation-no-svs"].at(ABLATION_OBSTACLES)
        sections["rl-table2"] = ablation_markdown(
            PAPER_TABLE2, {"m^o": no_svs, "m^o & m^h": shipped}
        )
    if "rl-table3" in wanted:
        no_gru = results["ablation-no-gru"].at(ABLATION_OBSTACLES)
        ours = {"no GRU": no_gru, "GRU 128": shipped, "GRU 512": None}
        sections["rl-table3"] = ablation_markdown(PAPER_TABLE3, ours)
    return sections
