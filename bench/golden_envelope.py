"""The golden mission's behavioural envelope: what city small looks like over many seeds.

A closed-loop mission turns the last bit of a ray's depth into another path, so its exact
figures hold only on the kind of machine that made them. What holds everywhere is its
behaviour: every vehicle detected and inspected, no false target, no collision, and layer
populations, localisation error, coverage and mission time of the size the seeds show. The
envelope is, per figure, the [min, max] over the recorded seeds' runs that did the mission's
job (:func:`did_the_job`: a run that misses a vehicle or collides is a failure to report, not a
behaviour to allow); the continuous figures are widened by ``WIDENING`` (10 %) of each bound,
the outcome figures (counts of targets, levels, detections, false targets, collisions) are not
widened at all.

``tests/missions/xflie/test_golden.py`` holds the golden mission to it on every machine, beside the
exact figures where the machine matches a golden file; ``bench/reproduction.py --only
golden-envelope`` records the seeds' figures from its city small runs into ``ENVELOPE``.

Whether the envelope holds on another kind of machine is measured here too: run as a script,
this module runs the same missions on another of OpenBLAS's kernel sets (``OPENBLAS_CORETYPE``,
the path an AVX2 processor takes is ``Haswell``), a floating-point path of its own, and records
them as held-out runs in ``ENVELOPE`` (``held_out``), which the test checks against the band
they were not part of. Regenerating the envelope keeps them while the code is the same (the
source hash its runs recorded) and drops them otherwise: run this again then.

Run: ``.venv/bin/python bench/golden_envelope.py --blas-kernels Haswell --seeds 0-9``
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from seminspect.core.io import atomic_write_text

ENVELOPE = (
    Path(__file__).resolve().parents[1]
    / "tests/missions/xflie/data/golden/city-small-envelope.json"
)
FORMAT = "seminspect.golden-envelope"
#: How far each bound of a continuous figure is widened, as a share of the bound.
WIDENING = 0.10
#: Figures whose band is exactly the seeds' [min, max]: a mission that misses a vehicle,
#: keeps a false one, collides or stops early has changed its behaviour.
OUTCOMES = (
    "completed",
    "true_targets",
    "matched_targets",
    "inspected_targets",
    "false_targets",
    "detected_pct",
    "inspected_pct",
    "collisions",
    "target_nodes",
    "target_edges",
    "level_nodes",
    "level_edges",
)
#: Figures that move from seed to seed (and machine to machine): widened by ``WIDENING``.
CONTINUOUS = (
    "pose_nodes",
    "pose_edges",
    "feature_nodes",
    "feature_edges",
    "unified_nodes",
    "unified_edges",
    "reconciled_pct",
    "rmse_xy_m",
    "surface_coverage_pct",
    "bbox_volume_m3",
    "sim_time_s",
    "distance_m",
)
FIGURES = OUTCOMES + CONTINUOUS

Band = tuple[float, float]


def envelope_figures(run: Mapping[str, Any]) -> dict[str, float]:
    """The envelope's figures of one run, from its ``metrics.json`` or from a golden file (which
    holds the same keys); a missing key raises ``KeyError``, never an empty figure."""
    t3, t6, targets, mission = run["table3"], run["table6"], run["targets"], run["mission"]
    return {
        "completed": float(run["state"] == "completed"),
        "true_targets": targets["true"],
        "matched_targets": targets["matched"],
        "inspected_targets": targets["inspected"],
        "false_targets": targets["false_targets"],
        "detected_pct": t3["detected_pct"],
        "inspected_pct": t3["inspected_pct"],
        "collisions": mission["collisions"],
        "target_nodes": t3["target"][0],
        "target_edges": t3["target"][1],
        "level_nodes": t3["level"][0],
        "level_edges": t3["level"][1],
        "pose_nodes": t3["pose"][0],
        "pose_edges": t3["pose"][1],
        "feature_nodes": t3["feature"][0],
        "feature_edges": t3["feature"][1],
        "unified_nodes": t3["unified"][0],
        "unified_edges": t3["unified"][1],
        "reconciled_pct": t3["reconciled_pct"],
        "rmse_xy_m": t6["localisation_rmse_m"],
        "surface_coverage_pct": t6["surface_coverage_pct"],
        "bbox_volume_m3": t6["bbox_volume_m3"],
        "sim_time_s": mission["sim_time_s"],
        "distance_m": mission["distance_m"],
    }


def did_the_job(run: Mapping[str, float]) -> bool:
    """Whether a run completed with every vehicle detected and inspected, no false target and
    no collision."""
    return (
        run["completed"] == 1
        and run["matched_targets"] == run["inspected_targets"] == run["true_targets"]
        and run["false_targets"] == 0
        and run["collisions"] == 0
    )


def envelope_runs(document: Mapping[str, Any]) -> list[dict[str, Any]]:
    """The recorded runs the envelope is made of: those that did the mission's job."""
    return [run for run in document["runs"] if did_the_job(run)]


def bands(runs: Iterable[Mapping[str, float]]) -> dict[str, Band]:
    """Each figure's band over ``runs`` (envelope figures): [min, max], the continuous ones
    widened by ``WIDENING`` of each bound (all figures are non-negative)."""
    runs = list(runs)
    if not runs:
        raise ValueError("an envelope needs at least one run")
    result = {}
    for name in FIGURES:
        values = [float(run[name]) for run in runs]
        low, high = min(values), max(values)
        if name in CONTINUOUS:
            low, high = low * (1 - WIDENING), high * (1 + WIDENING)
        result[name] = (low, high)
    return result


def outside(figures: Mapping[str, float], envelope: Mapping[str, Band]) -> list[str]:
    """Every figure of a run outside its band, one phrase each (empty: inside the envelope)."""
    return [
        f"{name} {figures[name]:.6g} outside [{low:.6g}, {high:.6g}]"
        for name, (low, high) in envelope.items()
        if not low <= figures[name] <= high
    ]


def read_envelope(path: Path = ENVELOPE) -> dict[str, Any]:
    """The recorded envelope: its configuration, where it was made and each seed's figures."""
    document = json.loads(path.read_text(encoding="utf-8"))
    if document.get("format") != FORMAT:
        raise ValueError(f"{path} is not a {FORMAT} file")
    return document


def envelope_document(
    config: Mapping[str, Any], made_on: Mapping[str, Any], runs: Mapping[int, Mapping[str, Any]]
) -> dict[str, Any]:
    """The file ``bench/reproduction.py`` records: each seed's envelope figures (from its
    metrics) and the code and machine that made them."""
    return {
        "format": FORMAT,
        "version": 1,
        "config": dict(config),
        "made_on": dict(made_on),
        "runs": [{"seed": seed, **envelope_figures(runs[seed])} for seed in sorted(runs)],
    }


def run_on_other_path(kernels: str, seed: int, out: Path) -> dict[str, Any]:
    """The golden configuration's mission for ``seed`` in a process whose OpenBLAS takes the
    ``kernels`` set: its envelope figures and the platform it recorded."""
    environment = {**os.environ, "OPENBLAS_CORETYPE": kernels}
    command = [sys.executable, "-m", "seminspect", "mission", "--world", "city"]
    command += ["--scenario", "small", "--seed", str(seed), "--no-pictures", "--out", str(out)]
    done = subprocess.run(command, env=environment, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["no message"])[-1]
        raise SystemExit(f"the mission of seed {seed} failed: {last}")
    metrics = json.loads((out / "metrics.json").read_text(encoding="utf-8"))
    config = json.loads((out / "config.json").read_text(encoding="utf-8"))
    return {"seed": seed, "platform": config["code"]["platform"], **envelope_figures(metrics)}


def _seed_list(text: str) -> list[int]:
    low, _, high = text.partition("-")
    return list(range(int(low), int(high or low) + 1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--blas-kernels", required=True, help="an OPENBLAS_CORETYPE, e.g. Haswell")
    parser.add_argument("--seeds", type=_seed_list, default=_seed_list("0-9"), help="e.g. 0-9")
    args = parser.parse_args()
    document = read_envelope()
    held_out = []
    with tempfile.TemporaryDirectory(prefix="envelope-") as scratch:
        for seed in args.seeds:
            run = run_on_other_path(args.blas_kernels, seed, Path(scratch) / f"seed{seed}")
            if run["platform"]["blas_kernels"] != args.blas_kernels:
                raise SystemExit(f"OpenBLAS did not take the {args.blas_kernels} kernels here")
            verdict = outside(run, bands(envelope_runs(document))) or ["inside"]
            print(f"seed {seed}: {'; '.join(verdict)}", flush=True)
            held_out.append(run)
    kept = [r for r in document.get("held_out", []) if r["platform"] != held_out[0]["platform"]]
    document["held_out"] = kept + held_out
    atomic_write_text(ENVELOPE, json.dumps(document, indent=1) + "\n")


if __name__ == "__main__":
    main()
