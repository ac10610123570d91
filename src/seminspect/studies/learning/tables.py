"""Markdown tables of learned-inspection evaluations beside 004 Tables I-III.

Each table puts the paper's rows first and ours under them, one measure per block, so a reader
compares numbers in the same column: coverage lenient (within ``inspect_range``) and strict (of
the feasible faces, with its 95 % interval), the distance score, crash % (with its Wilson 95 %
interval) and timeout %. The paper reports one coverage; it stands beside both of ours.
Percentages have one decimal, as in the paper. :func:`generalisation_markdown` shows policies
on object shapes, marking those they never met in training; :func:`policies_markdown` sets
whole policies (the shipped one, the next one in training, its ablations) side by side.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import NamedTuple

from seminspect.missions.learning.env_config import TARGET_SHAPES, TargetShape
from seminspect.missions.learning.evaluation import (
    PAPER_TABLE1,
    PAPER_TABLE2,
    PAPER_TABLE3,
    EvaluationResult,
    ObstacleResult,
    interval_text,
)

#: The sections of docs/reproduction.md, and the stored evaluations (file stems) each needs.
SECTIONS = ("rl-table1", "rl-table2", "rl-table3", "rl-shapes", "rl-retrained")
#: The shapes beside Table I's cylinders in the generalisation table, and their evaluations.
OTHER_SHAPES: tuple[TargetShape, ...] = ("box", "sphere", "t-pipe")
SHAPE_EVALUATIONS = tuple(
    f"shape-{controller}-{shape}" for controller in ("learned", "orbit") for shape in OTHER_SHAPES
)
NEEDS = {
    "rl-table1": ("table1-learned", "table1-orbit", "table1-random"),
    "rl-table2": ("table1-learned", "ablation-no-svs"),
    "rl-table3": ("table1-learned", "ablation-no-gru"),
    "rl-shapes": ("table1-learned", "table1-orbit", *SHAPE_EVALUATIONS),
    "rl-retrained": (
        "table1-learned",
        "v2-main",
        "v2-main-2m",
        "v2-no-svs",
        "v2-no-gru",
        "v3-main",
        "v3-no-svs",
        "v3-no-gru",
        "v3-gru-512",
        "v4-tune",
        "v4-main",
        "table1-orbit",
    ),
}
#: 004 Tables II and III are measured in rooms with nine obstacles.
ABLATION_OBSTACLES = 9


class Measure(NamedTuple):
    """One block of a table: its label, the paper's column (None: 004 has none), our cell."""

    label: str
    paper: int | None
    cell: Callable[[ObstacleResult], str]


STRICT = Measure(
    "strict coverage %", 0, lambda r: interval_text(r.strict_coverage_pct, r.strict_coverage_ci)
)
CRASH = Measure("crash %", 1, lambda r: interval_text(r.crash_pct, r.crash_ci))
MEASURES = (
    Measure("coverage % (lenient)", 0, lambda r: f"{r.coverage_pct:.1f}"),
    STRICT,
    Measure("distance score", None, lambda r: f"{r.distance_score:.2f}"),
    CRASH,
    Measure("timeout %", 2, lambda r: f"{r.timeout_pct:.1f}"),
)


def _cells(values: Sequence[float | str | None]) -> str:
    """Table cells: one decimal for numbers, text as given, "-" for a missing paper value."""
    return " | ".join("-" if v is None else v if isinstance(v, str) else f"{v:.1f}" for v in values)


def _paper(row: tuple[float, float, float] | None, measure: Measure) -> float | None:
    return None if row is None or measure.paper is None else row[measure.paper]


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
    for measure in MEASURES:
        if measure.paper is not None:
            paper = [_paper(PAPER_TABLE1.get(k), measure) for k in counts]
            lines.append(f"| {measure.label} | 004 (Aerial Gym, GPU) | {_cells(paper)} |")
        for name, result in results.items():
            ours = [measure.cell(result.at(k)) for k in counts]
            lines.append(f"| {measure.label} | {name} | {_cells(ours)} |")
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
    for measure in MEASURES:
        if measure.paper is not None:
            values = [_paper(paper[c], measure) for c in columns]
            lines.append(f"| {measure.label} | 004 | {_cells(values)} |")
        row = [_measure(ours.get(c), measure) for c in columns]
        lines.append(f"| {measure.label} | ours | {_cells(row)} |")
    episodes = sorted({r.episodes for r in ours.values() if r is not None})
    lines.append("")
    lines.append(f"Episodes per cell: {', '.join(str(n) for n in episodes)}.")
    return "\n".join(lines)


def _measure(result: ObstacleResult | None, measure: Measure) -> str:
    return "not trained" if result is None else measure.cell(result)


def generalisation_markdown(
    results: Mapping[str, Mapping[str, EvaluationResult]],
    trained: Mapping[str, Sequence[str]],
    obstacles: int = ABLATION_OBSTACLES,
) -> str:
    """Strict coverage and crash % of each policy (rows) on each object shape (columns).

    ``results`` maps a policy label to its evaluations by shape, ``trained`` the label to the
    shapes its training rooms held: a shape outside them is marked "(unseen)", the test of a
    policy trained without a shape and evaluated on it. A shape not evaluated shows "-".
    """
    shapes = [s for s in TARGET_SHAPES if any(s in by_shape for by_shape in results.values())]
    lines = [
        "| measure | policy | " + " | ".join(shapes) + " |",
        "|---|---|" + "---:|" * len(shapes),
    ]
    for measure in (STRICT, CRASH):
        for name, by_shape in results.items():
            cells = [
                None
                if shape not in by_shape
                else measure.cell(by_shape[shape].at(obstacles))
                + ("" if shape in trained[name] else " (unseen)")
                for shape in shapes
            ]
            lines.append(f"| {measure.label} | {name} | {_cells(cells)} |")
    episodes = sorted(
        {r.at(obstacles).episodes for by_shape in results.values() for r in by_shape.values()}
    )
    lines.append("")
    lines.append(
        f"{obstacles} obstacles; episodes per cell: {', '.join(str(n) for n in episodes)}."
    )
    return "\n".join(lines)


def policies_markdown(
    results: Mapping[str, EvaluationResult], obstacles: int = ABLATION_OBSTACLES
) -> str:
    """Every measure (columns) of each policy (rows) at one obstacle count, 004's row first.

    ``results`` maps a row label to its evaluation; each must hold ``obstacles``.
    """
    lines = [
        "| policy | " + " | ".join(m.label for m in MEASURES) + " |",
        "|---|" + "---:|" * len(MEASURES),
    ]
    paper = PAPER_TABLE1.get(obstacles)
    lines.append(f"| 004 (Aerial Gym, GPU) | {_cells([_paper(paper, m) for m in MEASURES])} |")
    for name, result in results.items():
        row = result.at(obstacles)
        lines.append(f"| {name} | {_cells([m.cell(row) for m in MEASURES])} |")
    episodes = sorted({r.at(obstacles).episodes for r in results.values()})
    lines.append("")
    lines.append(
        f"{obstacles} obstacles; episodes per cell: {', '.join(str(n) for n in episodes)}."
    )
    return "\n".join(lines)


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
    if "rl-shapes" in wanted:
        sections["rl-shapes"] = _shapes_section(results)
    if "rl-retrained" in wanted:
        rows = {results[n].policy: results[n] for n in NEEDS["rl-retrained"]}
        sections["rl-retrained"] = policies_markdown(rows)
    return sections


def _shapes_section(results: Mapping[str, EvaluationResult]) -> str:
    """The generalisation table from Table I's cylinders and the other shapes' evaluations.

    A learned policy's training shapes come from the env config its evaluation recorded; a
    baseline has no training, so no shape is unseen for it.
    """
    by_policy: dict[str, dict[str, EvaluationResult]] = {}
    trained: dict[str, Sequence[str]] = {}
    for name in NEEDS["rl-shapes"]:
        result = results[name]
        (shape,) = result.config.target_shapes
        by_policy.setdefault(result.policy, {})[shape] = result
        own = result.policy_env_config
        trained[result.policy] = TARGET_SHAPES if own is None else own.target_shapes
    return generalisation_markdown(by_policy, trained)
