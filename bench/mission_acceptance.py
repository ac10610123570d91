"""Reproduce 000 Tables 3 and 6 in simulation: missions over scenarios and seeds.

Runs the default mission (realistic noise) on city small, medium and large with seeds 0-2,
and once on campus, subterranean and both collapsed-building scenarios, then prints a Markdown
table per run with the paper's columns, the aggregate acceptance figures of issue 4 (targets
detected >= 95 %, inspected 100 % of detected, localisation RMSE <= 0.25 m, every layer
populated, no collision) and the paper's own rows beside ours.

The figures do not depend on the machine's speed (simulated time drives the robot; everything
is seeded), but on its kind of CPU (docs/reproduction.md, "Reproducing on another machine");
the wall-clock columns vary from run to run.

Run: ``.venv/bin/python bench/mission_acceptance.py [--out runs/acceptance] [--json out.json]``
(``--reuse`` reads completed runs of the same configuration instead of running them again).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Iterator
from pathlib import Path

from seminspect.missions.xflie.config import make_config, resolve
from seminspect.missions.xflie.layout import read_metrics_document, reusable_mission
from seminspect.missions.xflie.run import run_mission

CITY = [("city", scenario, seed) for scenario in ("small", "medium", "large") for seed in (0, 1, 2)]
OTHERS = [
    ("campus", None, 0),
    ("subterranean", None, 0),
    *(
        ("collapsed-buildings", scenario, seed)
        for scenario in ("fire-station", "industrial")
        for seed in (0, 1, 2)
    ),
]

#: 000 Table 3 (simulation) and Table 6 (xFLIE rows): detected/inspected %, RMSE m.
PAPER = {
    "small": {"t3": "6/9 10/5 106/101 68/36, 138/146, 27.3 %", "det": "100/100", "rmse": 0.17},
    "medium": {
        "t3": "11/21 21/11 253/244 102/55, 298/310, 22.3 %",
        "det": "100/100",
        "rmse": 0.195,
    },
    "large": {"t3": "20/40 40/23 469/452 219/121, 572/581, 23.5 %", "det": "95/100", "rmse": 0.24},
}


def row(world: str, scenario: str | None, seed: int, metrics: dict) -> str:
    t3, t6, m = metrics["table3"], metrics["table6"], metrics["mission"]
    pops = " ".join("/".join(map(str, t3[k])) for k in ("target", "level", "pose", "feature"))
    rmse = t6["localisation_rmse_m"]
    name = " ".join(filter(None, (world, scenario)))
    return (
        f"| {name} | {seed} | {pops} | {'/'.join(map(str, t3['unified']))} "
        f"| {t3['reconciled_pct']:.1f} | {t3['detected_pct']:.0f}/{t3['inspected_pct']:.0f} "
        f"| {metrics['targets']['false_targets']} | {'-' if rmse is None else f'{rmse:.3f}'} "
        f"| {_f(t6['surface_coverage_pct'], 1)} | {t6['bbox_volume_m3']:.0f} "
        f"| {m['collisions']} | {m['level_endings']['similarity']}/{m['level_endings']['cap']} "
        f"| {m['sim_time_s']:.0f} | {m['real_time_factor']:.1f} |"
    )


def _f(value: float | None, digits: int) -> str:
    return "-" if value is None else f"{value:.{digits}f}"


HEADER = (
    "| run | seed | Target Level Pose Feature | Unified | Reconciled % | Detected/Inspected % "
    "| false targets | RMSE xy (m) | surface coverage % | box volume (m^3) | collisions "
    "| levels by eq 8 / cap | sim s | x real time |\n" + "|" + "---|" * 14
)


def run_acceptance(
    runs: list[tuple[str, str | None, int]], out_dir: Path, *, reuse: bool
) -> Iterator[dict]:
    """Each run's metrics (tagged with its world, scenario and seed), run or read from
    ``out_dir`` when ``reuse`` and a completed run of the same configuration is there."""
    for world, scenario, seed in runs:
        config = resolve(make_config({"world": world, "scenario": scenario, "seed": seed}))
        out = out_dir / f"{world}-{scenario or 'default'}-seed{seed}"
        reused = reusable_mission(out, config) if reuse else None
        if reused:
            metrics = read_metrics_document(out)
        else:
            if reused is not None:
                print(f"running {out.name} again: {reused.reason}", file=sys.stderr, flush=True)
            metrics = run_mission(config, out).metrics.to_json()
        yield {**metrics, "run": {"world": world, "scenario": scenario, "seed": seed}}


def acceptance_lines(results: list[dict]) -> list[str]:
    """Issue 4's acceptance figures per city scenario, the paper's beside them."""
    lines = []
    for scenario in ("small", "medium", "large"):
        group = [
            r for r in results if r["run"]["world"] == "city" and r["run"]["scenario"] == scenario
        ]
        if not group:
            continue
        detected = min(r["table3"]["detected_pct"] for r in group)
        inspected = min(r["table3"]["inspected_pct"] for r in group)
        rmse = max(r["table6"]["localisation_rmse_m"] or 0.0 for r in group)
        populated = all(
            min(min(r["table3"][k]) for k in ("target", "level", "pose", "feature")) > 0
            for r in group
        )
        collisions = sum(r["mission"]["collisions"] for r in group)
        paper = PAPER[scenario]
        lines.append(
            f"- {scenario} ({len(group)} seeds): detected >= {detected:.0f} %, inspected >= "
            f"{inspected:.0f} %, worst RMSE {rmse:.3f} m, every layer populated: {populated}, "
            f"collisions {collisions}; paper: {paper['det']} %, RMSE {paper['rmse']} m, "
            f"Table 3 {paper['t3']}"
        )
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="runs/acceptance", help="where the run directories go")
    parser.add_argument("--json", help="also write every run's metrics to this file")
    parser.add_argument("--city-only", action="store_true")
    parser.add_argument(
        "--reuse", action="store_true", help="read completed runs of the same config in --out"
    )
    args = parser.parse_args()
    runs = CITY + ([] if args.city_only else OTHERS)
    print(HEADER)
    results = []
    for metrics in run_acceptance(runs, Path(args.out), reuse=args.reuse):
        results.append(metrics)
        run = metrics["run"]
        print(row(run["world"], run["scenario"], run["seed"], metrics), flush=True)
    print()
    print("City acceptance (issue 4): ")
    print("\n".join(acceptance_lines(results)))
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1), encoding="utf-8")


if __name__ == "__main__":
    main()
