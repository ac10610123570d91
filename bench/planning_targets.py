"""Were issue 5's targets met? Judges a planning study's ``planning.json``.

The study (``seminspect bench planning --out DIR``) measures; this script holds the targets it
was built to meet and says, for each, the measured figure and whether it was met:

* the hierarchical planner (HP) at least 1,000x faster than the volumetric planner (VP) at
  0.5 m on every city-large query (searches only, and end to end);
* refined HP paths at most 1.15x the VP length on average, and refined HP planning at least
  100x faster;
* HP time growing sub-linearly with the number of vehicles (scaling study).

Usage: ``python bench/planning_targets.py bench-planning/planning.json``
"""

from __future__ import annotations

import argparse
import math
import statistics
from pathlib import Path
from typing import Any

from seminspect.core.io import read_versioned_json
from seminspect.studies.xflie.scaling import growth_exponent
from seminspect.studies.xflie.tables import STUDY_FORMAT

TIME_RATIO = 1000.0
REFINED_LENGTH = 1.15
REFINED_TIME_RATIO = 100.0
GROWTH = 1.0
RESOLUTION = 0.5


def _at_resolution(query: dict[str, Any]) -> dict[str, Any]:
    return next(v for v in query["vp"] if v["resolution"] == RESOLUTION)


def targets_met(document: dict[str, Any]) -> dict[str, Any]:
    """Each target with the measured figure it is judged on."""
    result: dict[str, Any] = {}
    runs = document["table5"]
    large = [_at_resolution(q) for r in runs if r["scenario"] == "large" for q in r["queries"]]
    if large:
        search = min(v["time_ratio_search"] for v in large)
        query = min(v["time_ratio_end_to_end"] for v in large)
        result["time_ratio_large"] = {
            "target": f">= {TIME_RATIO:g}x at 0.5 m on every city-large query",
            "min_search": search,
            "min_end_to_end": query,
            "met_search": search >= TIME_RATIO,
            "met_end_to_end": query >= TIME_RATIO,
        }
    every = [q for r in runs for q in r["queries"]]
    if every:
        lengths = [_at_resolution(q)["refined_length_ratio"] for q in every]
        speed = [_at_resolution(q)["time_s"] / (q["hp"]["query_s"] + q["refine_s"]) for q in every]
        mean_length = statistics.fmean(v for v in lengths if v is not None and math.isfinite(v))
        result["refined"] = {
            "target": f"mean refined length <= {REFINED_LENGTH}x the volumetric at 0.5 m, "
            f"refined planning >= {REFINED_TIME_RATIO:g}x faster",
            "mean_length_ratio": mean_length,
            "min_time_ratio": min(speed),
            "median_time_ratio": statistics.median(speed),
            "met_length": mean_length <= REFINED_LENGTH,
            "met_time": min(speed) >= REFINED_TIME_RATIO,
        }
    points = document["scaling"]
    if len(points) >= 2:
        sizes = [p["targets"] for p in points]
        search = growth_exponent(sizes, [p["hp_search_s"] for p in points])
        plan = growth_exponent(sizes, [p["hp_plan_s"] for p in points])
        result["growth"] = {
            "target": f"hierarchical time grows sub-linearly over {min(sizes)} -> {max(sizes)}",
            "exponent_search": search,
            "exponent_plan": plan,
            "met": max(search, plan) < GROWTH,
        }
    return result


def _verdict(met: bool) -> str:
    return "met" if met else "not met"


def targets_markdown(met: dict[str, Any]) -> str:
    lines = ["## Issue 5's targets", ""]
    if "time_ratio_large" in met:
        t = met["time_ratio_large"]
        lines.append(
            f"- {t['target']}: smallest ratio {t['min_search']:,.0f}x (searches only, "
            f"{_verdict(t['met_search'])}), {t['min_end_to_end']:,.0f}x "
            f"(end to end, {_verdict(t['met_end_to_end'])})."
        )
    if "refined" in met:
        t = met["refined"]
        lines.append(
            f"- {t['target']}: mean refined length ratio {t['mean_length_ratio']:.3f} "
            f"({_verdict(t['met_length'])}); refined planning {t['min_time_ratio']:,.0f}x to "
            f"{t['median_time_ratio']:,.0f}x (min, median) faster ({_verdict(t['met_time'])})."
        )
    if "growth" in met:
        t = met["growth"]
        lines.append(
            f"- {t['target']}: time ~ targets^{t['exponent_search']:.2f} (searches), "
            f"^{t['exponent_plan']:.2f} (whole plan) ({_verdict(t['met'])})."
        )
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", type=Path, help="planning.json of seminspect bench planning")
    document = read_versioned_json(parser.parse_args().study, STUDY_FORMAT, [1])
    print(targets_markdown(targets_met(document)), end="")


if __name__ == "__main__":
    main()
