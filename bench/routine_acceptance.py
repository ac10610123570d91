"""Reproduce 002's routine-inspection results in simulation and check issue 11's figures.

Runs, on the 20 m mine drift with the paper's parameters (d_view 2 m, γ_H 0.6, α 69.5°,
β 45°, Γ_t 0.5), each scenario over ``SEEDS`` (each seed draws its own site and change):

* nominal (002 Fig 8), adaptive;
* receding (Figs 9 vs 11) and advancing, adaptive and non-adaptive on one M_H;
* obstructed, adaptive;

then times SA-TSP against LKH (elkai) on the tasks' view sets and on view grids of growing
size. Prints the Markdown tables (mean ± standard deviation over the seeds, counts as median
and range) and the acceptance checks (how many seeds meet each), and writes every figure to a
JSON file. Simulated figures do not depend on the machine's speed; the timings do.
``bench/reproduction.py --only routine`` writes the same tables into docs/reproduction.md.

Run: ``.venv/bin/python bench/routine_acceptance.py [--out runs/routine-acceptance]
[--json routine-acceptance.json] [--seeds 0 1 2 3 4]``
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from reproduction_missions import seeds_cell
from seminspect.core.rng import make_rng
from seminspect.missions.routine.executive import RoutineConfig
from seminspect.missions.routine.run import PRIOR_FILE, run_routine
from seminspect.planning.global_views import InspectionRegion, grid_points
from seminspect.planning.tour import annealed_tour, reference_tour
from seminspect.report.markdown import mean_sd, median_range

SEEDS = (0, 1, 2, 3, 4)
#: Scenarios run adaptive alone, and those run both ways on one prior.
SINGLE = ("nominal", "obstructed")
PAIRED = ("receding", "advancing")
#: View grids for the tour comparison: rectangle width x height [m] on a wall.
GRIDS = ((2.4, 1.6), (6.0, 3.0), (12.0, 4.0), (24.0, 4.0))


def run_pair(out: Path, scenario: str, seed: int) -> dict:
    adaptive = run_routine(
        RoutineConfig(scenario=scenario, seed=seed), out / f"{scenario}-{seed}-a"
    )
    prior = adaptive.run_dir / PRIOR_FILE
    baseline = run_routine(
        RoutineConfig(scenario=scenario, seed=seed, adapt=False),
        out / f"{scenario}-{seed}-b",
        prior_path=prior,
    )
    return {"adaptive": adaptive.metrics, "baseline": baseline.metrics}


def pair_checks(pair: dict) -> dict[str, bool]:
    a, b = pair["adaptive"], pair["baseline"]
    after = a["view_distance_mae_after_deviation_m"]
    return {
        "distance error <= 0.3 m after adapting": after is not None and after <= 0.3,
        "utility +0.1 over baseline": a["viewpoint_utility_mean"]
        >= b["viewpoint_utility_mean"] + 0.1,
        "coverage above baseline": a["roi_coverage_pct"] > b["roi_coverage_pct"],
        "RMSE after Kabsch below before": a["rmse_after_kabsch_m"] < a["rmse_before_kabsch_m"],
    }


def tour_study() -> list[dict]:
    """SA-TSP against LKH on view grids of growing size (start 2 m off the grid's corner)."""
    config = RoutineConfig()
    rows = []
    for width, height in GRIDS:
        region = InspectionRegion(
            f"{width}x{height}",
            [
                [10.0, 0, 0.5],
                [10.0, width, 0.5],
                [10.0, width, 0.5 + height],
                [10.0, 0, 0.5 + height],
            ],
        )
        views = grid_points(region, config.view_constraints()) - [2.0, 0.0, 0.0]
        start = views[0] - [0.0, 2.0, 0.0]
        t0 = time.perf_counter()
        sa = annealed_tour(start, views, make_rng(0, "bench", "tour"))
        t1 = time.perf_counter()
        lkh = reference_tour(start, views)
        t2 = time.perf_counter()
        rows.append(
            {
                "views": len(views),
                "sa_length_m": sa.length,
                "lkh_length_m": lkh.length,
                "gap_pct": 100 * (sa.length / lkh.length - 1),
                "sa_ms": 1e3 * (t1 - t0),
                "lkh_ms": 1e3 * (t2 - t1),
            }
        )
    return rows


def single_checks(scenario: str, m: dict) -> dict[str, bool]:
    if scenario == "nominal":
        return {
            "Γ_s below Γ_t throughout": m["gamma_s_max"] < 0.5,
            "utility >= 0.7": m["viewpoint_utility_mean"] >= 0.7,
        }
    return {
        "every task completed": m["tasks_completed"] == m["tasks_total"],
        "no collision": m["collisions"] == 0,
    }


def run_studies(out: Path, seeds: tuple[int, ...] = SEEDS) -> dict:
    """Every scenario over ``seeds``: ``single[scenario][seed]`` the adaptive run's metrics,
    ``pairs[scenario][seed]`` the adaptive and non-adaptive runs on one prior."""
    results: dict = {"single": {}, "pairs": {}, "seeds": list(seeds)}
    for scenario in SINGLE:
        results["single"][scenario] = {
            seed: run_routine(
                RoutineConfig(scenario=scenario, seed=seed), out / f"{scenario}-{seed}"
            ).metrics
            for seed in seeds
        }
    for scenario in PAIRED:
        results["pairs"][scenario] = {seed: run_pair(out, scenario, seed) for seed in seeds}
    return results


def single_table(results: dict) -> str:
    """Nominal and obstructed runs over the seeds."""
    lines = [
        "| scenario | seeds | Γ_s max | mean utility | viewing-distance MAE m | ROI coverage % "
        "| task time s (first task) | tasks completed | collisions |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for scenario, runs in results["single"].items():
        ms = list(runs.values())
        lines.append(
            f"| {scenario} | {seeds_cell(list(runs))} "
            f"| {mean_sd((m['gamma_s_max'] for m in ms), 2)} "
            f"| {mean_sd((m['viewpoint_utility_mean'] for m in ms), 3)} "
            f"| {mean_sd((m['view_distance_mae_m'] for m in ms), 2)} "
            f"| {mean_sd((m['roi_coverage_pct'] for m in ms), 1)} "
            f"| {mean_sd((m['tasks'][0]['time_s'] for m in ms), 1)} "
            f"| {median_range(m['tasks_completed'] for m in ms)} of "
            f"{median_range(m['tasks_total'] for m in ms)} "
            f"| {median_range(m['collisions'] for m in ms)} |"
        )
    return "\n".join(lines)


def _change_m(metrics: dict) -> float:
    change = metrics["scenario"]["change"]
    return change.get("depth_m", change.get("advance_m", 0.0))


def pair_table(results: dict) -> str:
    """Receding and advancing, adaptive / non-adaptive, over the seeds."""
    lines = [
        "| scenario | seeds | change m | Γ_s max | distance MAE after (m) | utility "
        "| ROI coverage % | RMSE before / after Kabsch (m) | adapted cycles |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for scenario, pairs in results["pairs"].items():
        a = [pair["adaptive"] for pair in pairs.values()]
        b = [pair["baseline"] for pair in pairs.values()]

        def both(key: str, digits: int, a=a, b=b) -> str:
            return (
                f"{mean_sd((m[key] for m in a), digits)} / {mean_sd((m[key] for m in b), digits)}"
            )

        lines.append(
            f"| {scenario} | {seeds_cell(list(pairs))} | {mean_sd(map(_change_m, a), 2)} "
            f"| {mean_sd((m['gamma_s_max'] for m in a), 2)} "
            f"| {both('view_distance_mae_after_deviation_m', 2)} "
            f"| {both('viewpoint_utility_mean', 3)} | {both('roi_coverage_pct', 1)} "
            f"| {mean_sd((m['rmse_before_kabsch_m'] for m in a), 2)} / "
            f"{mean_sd((m['rmse_after_kabsch_m'] for m in a), 2)} "
            f"| {median_range(m['adapted_cycles'] for m in a)} of "
            f"{median_range(m['cycles'] for m in a)} |"
        )
    return "\n".join(lines)


def acceptance_checks(results: dict) -> dict[str, dict[int, dict[str, bool]]]:
    """Issue 11's checks, per scenario and seed."""
    checks: dict[str, dict[int, dict[str, bool]]] = {}
    for scenario, runs in results["single"].items():
        checks[scenario] = {seed: single_checks(scenario, m) for seed, m in runs.items()}
    for scenario, pairs in results["pairs"].items():
        checks[scenario] = {seed: pair_checks(pair) for seed, pair in pairs.items()}
    return checks


def acceptance_lines(checks: dict[str, dict[int, dict[str, bool]]]) -> list[str]:
    """One line per scenario and check: in how many seeds it is met, and which miss it."""
    lines = []
    for scenario, by_seed in checks.items():
        for check in next(iter(by_seed.values())):
            missed = [seed for seed, found in by_seed.items() if not found[check]]
            met = len(by_seed) - len(missed)
            plural = "s" if len(missed) > 1 else ""
            note = f" (not in seed{plural} {', '.join(map(str, missed))})" if missed else ""
            lines.append(f"- {scenario}: {check}: met in {met} of {len(by_seed)}{note}")
    return lines


def tours_table(tours: list[dict]) -> str:
    lines = ["| views | SA m | LKH m | gap % | SA ms | LKH ms |", "|---|---|---|---|---|---|"]
    lines += [
        f"| {r['views']} | {r['sa_length_m']:.2f} | {r['lkh_length_m']:.2f} | "
        f"{r['gap_pct']:.2f} | {r['sa_ms']:.0f} | {r['lkh_ms']:.0f} |"
        for r in tours
    ]
    return "\n".join(lines)


def task_gaps(results: dict) -> list[float]:
    """SA's gap to LKH on every task of every adaptive run [%]."""
    runs = [m for runs in results["single"].values() for m in runs.values()]
    runs += [pair["adaptive"] for pairs in results["pairs"].values() for pair in pairs.values()]
    return [t["tour"]["gap_pct"] for m in runs for t in m["tasks"] if "gap_pct" in t["tour"]]


def sections(out: Path, seeds: tuple[int, ...] = SEEDS) -> dict[str, str]:
    """The routine sections of docs/reproduction.md, from fresh runs under ``out``."""
    results = run_studies(out, seeds)
    tours = tour_study()
    gaps = task_gaps(results)
    lines = acceptance_lines(acceptance_checks(results))
    lines.append(
        f"- SA-TSP within 5 % of LKH on every task: {'met' if max(gaps) <= 5.0 else 'not met'} "
        f"(largest gap {max(gaps):.2f} % over {len(gaps)} tasks); on every grid: "
        f"{'met' if all(r['gap_pct'] <= 5.0 for r in tours) else 'not met'}"
    )
    return {
        "routine-single": single_table(results),
        "routine-pairs": pair_table(results),
        "routine-acceptance": "\n".join(lines),
        "routine-tours": tours_table(tours),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=Path("runs/routine-acceptance"))
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--seeds", type=int, nargs="+", default=list(SEEDS))
    args = parser.parse_args()
    results = run_studies(args.out, tuple(args.seeds))
    tours = tour_study()
    print("## nominal and obstructed (002 Fig 8; paper: Γ_s below 0.5 throughout, utility 0.71)")
    print(single_table(results))
    print("\n## receding and advancing: adaptive / non-adaptive")
    print(pair_table(results))
    print("\n## SA-TSP against LKH (elkai)")
    print(tours_table(tours))
    print("\n## acceptance")
    print("\n".join(acceptance_lines(acceptance_checks(results))))
    print(f"- SA-TSP: largest gap to LKH on a task {max(task_gaps(results)):.2f} %")
    if args.json:
        results["tours"] = tours
        args.json.write_text(json.dumps(results, indent=1, default=float))


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
