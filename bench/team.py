"""Two robots against one: time to inspect every target, same world, same seeds.

For each seed it runs the one-robot xFLIE mission and the explorer + inspector team on the same
world (default: city large, 20 vehicles) and prints, per seed and over all seeds, the time the
mission finished (exploration done and every target inspected; the team's is the later of its
two clocks), the time the last target was inspected, when the team's exploration ended (the
last frontier step of either robot), what was found and inspected (and by which robot), how
long the inspector explored and waited, and the team's times as a ratio of the one robot's.
The target is a team at least 30 % faster.

Missions of city large take many minutes each, so runs go to ``--runs`` and a completed run of
the same configuration found there is read instead of run again (``--only one`` or ``--only
team`` lets several processes share the work; a last call without ``--only`` prints the table).

Run: ``.venv/bin/python bench/team.py [--scenario large] [--seeds 0 1 2] [--runs DIR]``
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from seminspect.missions.xflie.config import make_config, resolve
from seminspect.missions.xflie.layout import read_metrics_document
from seminspect.missions.xflie.run import run_mission
from seminspect.runs.directory import read_run_config
from seminspect.runs.status import read_run_status

KINDS = {"one": None, "team": ["explorer", "inspector"]}
TARGET_SPEEDUP_PCT = 30.0


def run_or_reuse(values: dict[str, Any], out: Path) -> str:
    """Run the mission into ``out`` unless a completed run of the same configuration is there."""
    config = make_config(values)
    wanted = resolve(config).model_dump(mode="json")
    done = (out / "metrics.json").is_file() and read_run_status(out).state == "completed"
    if done and read_run_config(out) == wanted:
        return "reused"
    run_mission(config, out)
    return "ran"


def figures(out: Path) -> dict[str, Any]:
    """Finish time, last inspection, distances and target counts of a completed run."""
    metrics = read_metrics_document(out)
    events = [json.loads(line) for line in (out / "events.jsonl").read_text().splitlines()]
    targets = metrics["targets"]
    robots = metrics.get("robots", {})
    driven = [r["mission"]["distance_m"] for r in robots.values()] or [
        metrics["mission"]["distance_m"]
    ]
    return {
        "finish_s": metrics["mission"]["sim_time_s"],
        "last_inspection_s": max(
            (e["t"] for e in events if e["event"] == "inspected"), default=float("nan")
        ),
        "inspecting_s_per_target": inspecting_seconds(events) / max(targets["inspected"], 1),
        "driven": " + ".join(f"{d:.0f}" for d in driven),
        "exploration_done_s": exploration_end(events) if robots else None,
        "inspected_by": (
            " + ".join(str(len(r["inspected"])) for r in robots.values()) if robots else None
        ),
        "inspector_wait_s": (
            robots["inspector"]["seconds_by_activity"].get("wait", 0.0) if robots else None
        ),
        "inspector_explore_s": (
            robots["inspector"]["seconds_by_activity"].get("explore", 0.0) if robots else None
        ),
        "found": f"{targets['matched']}/{targets['true']}",
        "inspected": targets["inspected"],
        "false": targets["false_targets"],
        "wall_s": metrics["mission"]["wall_time_s"],
    }


def exploration_end(events: list[dict[str, Any]]) -> float:
    """When the team's last exploration step (a survey or frontier step of either robot)
    ended."""
    return max(
        e["end"]
        for e in events
        if e["event"] == "activity" and e["activity"] in ("survey", "explore")
    )


def inspecting_seconds(events: list[dict[str, Any]]) -> float:
    """Simulated seconds from arriving at a target to its inspection's end, summed."""
    arrived, total = None, 0.0
    for event in events:
        if event["event"] == "arrived":
            arrived = event["t"]
        elif event["event"] == "inspected" and arrived is not None:
            total += event["t"] - arrived
    return total


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--world", default="city")
    parser.add_argument("--scenario", default="large")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--runs", type=Path, default=Path("runs/team-bench"))
    parser.add_argument("--only", choices=sorted(KINDS), help="run one kind, print nothing")
    args = parser.parse_args()

    rows: dict[int, dict[str, dict[str, Any]]] = {}
    for seed in args.seeds:
        for kind, robots in KINDS.items():
            if args.only and kind != args.only:
                continue
            out = args.runs / f"{args.world}-{args.scenario}-seed{seed}-{kind}"
            values = {"world": args.world, "scenario": args.scenario, "seed": seed}
            how = run_or_reuse(values | ({"robots": robots} if robots else {}), out)
            rows.setdefault(seed, {})[kind] = figures(out) | {"how": how}
    if args.only:
        return
    print_table(args, rows)


def print_table(args: argparse.Namespace, rows: dict[int, dict[str, dict[str, Any]]]) -> None:
    print(f"{args.world} {args.scenario}: one robot vs explorer + inspector (simulated seconds)")
    print(
        "| seed | one robot: finish | last inspection | driven (m) | team: finish "
        "| last inspection | exploration done | driven (explorer + inspector, m) "
        "| team / one (finish) |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    ratios = []
    for seed, kinds in rows.items():
        one, team = kinds["one"], kinds["team"]
        ratios.append(team["finish_s"] / one["finish_s"])
        print(
            f"| {seed} | {one['finish_s']:.0f} | {one['last_inspection_s']:.0f} "
            f"| {one['driven']} | {team['finish_s']:.0f} | {team['last_inspection_s']:.0f} "
            f"| {team['exploration_done_s']:.0f} | {team['driven']} | {ratios[-1]:.2f} |"
        )
    mean = sum(ratios) / len(ratios)
    faster = 100.0 * (1.0 - mean)
    verdict = "met" if faster >= TARGET_SPEEDUP_PCT else "not met"
    print(
        f"mean team / one (finish): {mean:.2f}; the team finishes {abs(faster):.0f} % "
        f"{'sooner' if faster >= 0 else 'later'} (target >= {TARGET_SPEEDUP_PCT:.0f} % sooner: "
        f"{verdict})"
    )
    for seed, kinds in rows.items():
        for kind, row in kinds.items():
            print(
                f"seed {seed} {kind}: found {row['found']}, inspected {row['inspected']}, "
                f"false {row['false']}, {row['inspecting_s_per_target']:.0f} s at each "
                f"inspected target, {row['how']} ({row['wall_s']:.0f} s wall)"
                + (
                    f"; inspected by explorer + inspector {row['inspected_by']}"
                    f", inspector explored {row['inspector_explore_s']:.0f} s"
                    f" and waited {row['inspector_wait_s']:.0f} s"
                    if row["inspector_wait_s"] is not None
                    else ""
                )
            )


if __name__ == "__main__":
    main()
