"""The Table 6 tables of the planning study (000 Table 6 analogue): each planner's missions over
the seeds beside the paper's cells, every run, and the RMSE over the targets two planners share."""

from __future__ import annotations

import math
import statistics
from collections.abc import Sequence

from seminspect.missions.xflie.config import inspects
from seminspect.report.markdown import mean_sd
from seminspect.studies.xflie.cells import num_cell
from seminspect.studies.xflie.missions import CITY_SCENARIOS, TABLE6_PLANNERS, MissionOutcome
from seminspect.studies.xflie.paper import PAPER_TABLE6


def common_target_rmse(outcomes: Sequence[MissionOutcome], planner: str) -> float | None:
    """Horizontal RMSE of ``planner``'s missions over the targets that it and its counterpart
    (:func:`_other_planner`) both scored in the same scenario and seed, pooled over the runs:
    two planners on one target set (each mission's own RMSE covers whatever it scored within
    its budget)."""
    runs = {(o.scenario, o.seed, o.planner): o for o in outcomes}
    errors = []
    for (scenario, seed, name), outcome in runs.items():
        other = runs.get((scenario, seed, _other_planner(name)))
        if name != planner or other is None:
            continue
        shared = outcome.inspected_errors.keys() & other.inspected_errors.keys()
        errors += [outcome.inspected_errors[truth] for truth in shared]
    return math.sqrt(statistics.fmean(e * e for e in errors)) if errors else None


def _other_planner(planner: str) -> str:
    """xFLIE is compared with the volumetric baseline; each baseline (the frontier explorer
    too) with xFLIE."""
    return "volumetric" if planner == "hierarchical" else "hierarchical"


def table6_summary(outcomes: Sequence[MissionOutcome]) -> str:
    """One row per scenario and planner over the seeds: mean ± standard deviation, the paper's
    figure in brackets where 000 Table 6 gives one."""
    lines = [
        "| Scenario | Planner | seeds | planning load % | CPU load % (paper) "
        "| coverage m³ (paper) | RMSE m, own targets (paper) | RMSE m, common targets "
        "| inspected / true | sim s |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    groups: dict[tuple[str, str], list[MissionOutcome]] = {}
    for o in outcomes:
        groups.setdefault((o.scenario, o.planner), []).append(o)
    for (scenario, planner), runs in groups.items():
        cpu, cover, rmse = PAPER_TABLE6.get(scenario, {}).get(planner, (None, None, None))
        common = common_target_rmse([o for o in outcomes if o.scenario == scenario], planner)
        inspected = "; ".join(f"{_scored_count(o)} / {o.true_targets}" for o in runs)
        lines.append(
            f"| {scenario} | {planner} | {', '.join(str(o.seed) for o in runs)} "
            f"| {mean_sd((o.planning_load_pct for o in runs), 3)} "
            f"| {mean_sd((o.cpu_load_pct for o in runs), 1)} ({num_cell(cpu, 1)}) "
            f"| {mean_sd((o.bbox_volume_m3 for o in runs), 1)} ({num_cell(cover, 1)}) "
            f"| {mean_sd((o.rmse_m for o in runs), 3)} ({num_cell(rmse, 3)}) "
            f"| {num_cell(common, 3)} | {inspected} | {mean_sd((o.sim_time_s for o in runs), 0)} |"
        )
    return "\n".join(lines) + "\n"


def merge_table6_rows(current: str, fresh: str) -> str:
    """``fresh`` (a :func:`table6_summary`) with the rows of ``current`` (an earlier one) for
    scenarios and planners it lacks: regenerating one planner's missions keeps the others' rows.
    Rows are ordered by scenario, then planner as in ``TABLE6_PLANNERS``."""
    header, rows = _table_rows(fresh)
    _, kept = _table_rows(current)
    by_key = {_row_key(row): row for row in kept} | {_row_key(row): row for row in rows}

    def order(key: tuple[str, str]) -> tuple[int, int, str, str]:
        scenario, planner = key
        return (_index(CITY_SCENARIOS, scenario), _index(TABLE6_PLANNERS, planner), *key)

    return "\n".join([*header, *(by_key[key] for key in sorted(by_key, key=order))]) + "\n"


def _table_rows(table: str) -> tuple[list[str], list[str]]:
    """A Markdown table's header lines (title and rule) and its rows."""
    lines = [line for line in table.splitlines() if line.startswith("|")]
    return lines[:2], lines[2:]


def _row_key(row: str) -> tuple[str, str]:
    """The scenario and planner cells of a Table 6 row."""
    cells = [cell.strip() for cell in row.strip("|").split("|")]
    return cells[0], cells[1]


def _index(names: Sequence[str], name: str) -> int:
    return names.index(name) if name in names else len(names)


def _scored_count(outcome: MissionOutcome) -> str:
    """Targets inspected, or for a mission that never inspects those found ("found 4")."""
    return str(outcome.inspected) if inspects(outcome.planner) else f"found {outcome.found}"


def table6_markdown(outcomes: Sequence[MissionOutcome]) -> str:
    lines = [
        "## Mission-level effect (000 Table 6 analogue; planning time charged to the robot)",
        "",
        table6_summary(outcomes),
        "Each run:",
        "",
        "| Scenario | seed | Planner | CPU load % (paper) | planning load % "
        "| coverage m³ (paper) | surface coverage % | RMSE m (paper) | inspected / true | sim s "
        "| planning wall s | route plans |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for o in outcomes:
        paper = PAPER_TABLE6.get(o.scenario, {}).get(o.planner)
        cpu, cover, rmse = paper if paper else (None, None, None)
        lines.append(
            f"| {o.scenario} | {o.seed} | {o.planner} "
            f"| {num_cell(o.cpu_load_pct, 1)} ({num_cell(cpu, 1)}) "
            f"| {num_cell(o.planning_load_pct, 3)} "
            f"| {num_cell(o.bbox_volume_m3, 1)} ({num_cell(cover, 1)}) "
            f"| {num_cell(o.surface_coverage_pct, 1)} "
            f"| {num_cell(o.rmse_m, 3)} ({num_cell(rmse, 3)}) "
            f"| {_scored_count(o)} / {o.true_targets} | {o.sim_time_s:.0f} "
            f"| {o.planning_wall_s:.2f} | {o.route_plans} |"
        )
    return "\n".join(lines) + "\n"
