"""Compare two sets of missions column by column: did a change (or another machine) move them?

Each set is a sweep (a directory holding ``sweep.csv``, or the CSV itself, such as
``docs/data/reproduction/missions.csv``, every mission behind docs/reproduction.md's tables).
Runs are grouped as the sweep groups them (world, scenario, settings); for every group in both
sets and every column that does not depend on wall-clock time, a two-sided Mann-Whitney U test
asks whether the two sets of seeds could come from one distribution. A column is flagged when
its p-value is below ``--alpha`` (0.05): that is the rule of CONTRIBUTING.md for changes of
behaviour, under which single runs may move but the statistics must stay in their band.

Mann-Whitney compares ranks, so it needs no assumption on the figures' distribution, and it does
not pair seeds: after a change of behaviour seed 3 is simply another mission, not the same one
moved. With 5 seeds a side the smallest possible p-value is 0.008, so only a clear shift can be
flagged; 10 a side see smaller ones. Over many columns a chance flag is expected now and then
(one in twenty columns at 0.05): rerun the flagged group with more seeds before believing it.

Run: ``.venv/bin/python bench/compare_runs.py BEFORE AFTER [--alpha 0.05] [--group NAME]``
(exit status 1 when a column is flagged).
"""

from __future__ import annotations

import argparse
import csv
import math
import statistics
import sys
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from scipy.stats import mannwhitneyu

from seminspect.missions.xflie.sweep import COLUMNS

#: Columns that measure the machine's speed and load, not the mission's behaviour.
WALL_CLOCK = frozenset({"avg_planning_ms", "cpu_load_pct", "planning_load_pct"})
BEHAVIOUR = tuple(name for name, _, _ in COLUMNS if name not in WALL_CLOCK)
ALPHA = 0.05

Runs = dict[str, list[dict[str, float]]]


def read_runs(path: Path) -> Runs:
    """Each group's finished runs (their behaviour columns) from a sweep's ``sweep.csv``."""
    table = path / "sweep.csv" if path.is_dir() else path
    try:
        text = table.read_text(encoding="utf-8")
    except OSError as exc:
        raise SystemExit(f"cannot read {table}: {exc.strerror or exc}") from None
    rows = list(csv.DictReader(text.splitlines()))
    if not rows or "group" not in rows[0]:
        raise SystemExit(f"{table} is not a sweep table (no 'group' column)")
    runs: Runs = {}
    for line, row in enumerate(rows, start=2):
        if row.get("state") == "failed":
            continue
        try:
            figures = {n: float(row[n]) for n in BEHAVIOUR if row.get(n) not in (None, "")}
        except ValueError as exc:
            raise SystemExit(f"{table}, line {line}: {exc}") from None
        runs.setdefault(row["group"], []).append(figures)
    return runs


@dataclass(frozen=True)
class Comparison:
    """One column of one group in both sets: medians, the test's p-value, and the verdict."""

    group: str
    column: str
    before: tuple[float, ...]
    after: tuple[float, ...]
    p_value: float
    flagged: bool

    def row(self) -> str:
        mark = "**differs**" if self.flagged else "same"
        return (
            f"| {self.group} | {self.column} | {len(self.before)} / {len(self.after)} "
            f"| {statistics.median(self.before):.4g} | {statistics.median(self.after):.4g} "
            f"| {self.p_value:.3g} | {mark} |"
        )


def p_value(before: Sequence[float], after: Sequence[float]) -> float:
    """Two-sided Mann-Whitney U p-value; 1 where both sets hold one and the same value (the
    test is undefined there, and nothing moved)."""
    if len(set(before) | set(after)) == 1:
        return 1.0
    return float(mannwhitneyu(before, after, alternative="two-sided").pvalue)


def compare(
    before: Mapping[str, list[dict[str, float]]],
    after: Mapping[str, list[dict[str, float]]],
    alpha: float = ALPHA,
    groups: Iterable[str] | None = None,
) -> list[Comparison]:
    """Every behaviour column of every group both sets hold (or of ``groups``)."""
    wanted = list(groups) if groups else [g for g in before if g in after]
    comparisons = []
    for group in wanted:
        for column in BEHAVIOUR:
            a = tuple(run[column] for run in before.get(group, []) if column in run)
            b = tuple(run[column] for run in after.get(group, []) if column in run)
            if len(a) < 2 or len(b) < 2 or not all(map(math.isfinite, a + b)):
                continue
            p = p_value(a, b)
            comparisons.append(Comparison(group, column, a, b, p, p < alpha))
    return comparisons


def report(comparisons: Sequence[Comparison], alpha: float) -> str:
    lines = [
        "| group | column | runs before / after | median before | median after | p | verdict |",
        "|---|---|---|---|---|---|---|",
        *(c.row() for c in comparisons),
    ]
    flagged = sum(c.flagged for c in comparisons)
    lines.append("")
    lines.append(
        f"{flagged} of {len(comparisons)} columns differ (two-sided Mann-Whitney U, alpha {alpha})"
    )
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("before", type=Path, help="sweep directory or sweep.csv")
    parser.add_argument("after", type=Path, help="sweep directory or sweep.csv")
    parser.add_argument("--alpha", type=float, default=ALPHA, help="significance level")
    parser.add_argument("--group", action="append", help="compare only this group (repeatable)")
    args = parser.parse_args(argv)
    if not 0 < args.alpha < 1:
        raise SystemExit(f"--alpha must lie between 0 and 1, got {args.alpha}")
    before, after = read_runs(args.before), read_runs(args.after)
    for group in args.group or []:
        if group not in before or group not in after:
            raise SystemExit(f"group {group!r} is not in both sets")
    comparisons = compare(before, after, args.alpha, args.group)
    if not comparisons:
        raise SystemExit("the two sets share no group with two or more runs to compare")
    print(report(comparisons, args.alpha))
    return 1 if any(c.flagged for c in comparisons) else 0


if __name__ == "__main__":
    sys.exit(main())
