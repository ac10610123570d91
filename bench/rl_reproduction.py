"""004 Tables I-III with the shipped policy, its ablations and the baselines, beside the paper.

Every controller meets the same rooms (seed 0, 100 episodes per obstacle count, 90 s each; the
rooms are drawn per batch and per room, see ``missions.learning.evaluation``) and is flown with
the observations and rewards of the environment it was trained in (its checkpoint's); each
learned evaluation records its checkpoint's SHA-256. The evaluations are kept as JSON in
``docs/data/rl/``; the tables of docs/reproduction.md are made from those files by
``seminspect.studies.learning``, and ``tests/studies/learning/test_tables.py`` checks that the
document still matches them.

* ``rl-table1``: the shipped policy, the orbit and the random controllers at 0/4/9/14/19
  obstacles (004 Table I);
* ``rl-table2``: the policy trained without the SVS map beside the shipped one, 9 obstacles;
* ``rl-table3``: the policy trained without a GRU beside the shipped one (GRU 128), 9 obstacles;
* ``rl-shapes``: the shipped policy and the orbit on the four object shapes, 9 obstacles (a
  shape the policy's training rooms never held is marked unseen);
* ``rl-retrained``: the policies trained in the paper's rooms, reward and maps (v2: f_t paid
  as is; v3: shaped), not shipped yet, beside the shipped policy and the orbit, 9 obstacles.

With Table I it also draws ``docs/images/rl-coverage.png``: coverage against time of the three
controllers at each obstacle count (mean and 5th-95th percentile, as 004 Fig 5), and
``docs/images/rl-training.png`` from the training logs kept in ``docs/data/rl/``.

The ablation checkpoints lie in ``bench/checkpoints/rl/`` (trained by the commands in
docs/learning.md). The default detector here is the simulator's privileged segmentation (the
paper's is also privileged: Aerial Gym's segmentation camera).

Every finished batch of rooms is kept in ``bench/.rl-batches/`` (ignored by git), named by the
evaluation, its checkpoint's SHA-256, a digest of the learning package's code, the versions of
numpy and torch, the env config, the seed and the batch: a stopped run resumes where it stopped,
and ``--obstacles`` shares one evaluation's counts among processes (each fills the store; a
last run without it assembles the JSON from the store in seconds).

Run: ``.venv/bin/python bench/rl_reproduction.py [--only rl-table1 ...] [--episodes N]``
"""

from __future__ import annotations

import argparse
import hashlib
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np
import torch

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import file_sha256
from seminspect.missions.learning.agent import load_controller, shipped_policy_path
from seminspect.missions.learning.baselines import Controller, OrbitController, RandomController
from seminspect.missions.learning.batches import BatchStore
from seminspect.missions.learning.env_config import TargetShape
from seminspect.missions.learning.evaluation import (
    EvaluationResult,
    controller_evaluation_config,
    evaluate,
)
from seminspect.missions.learning.rooms import TABLE1_OBSTACLES
from seminspect.report.figures import save_figure
from seminspect.report.markdown import rewrite_sections
from seminspect.report.rl import coverage_figure, training_figure
from seminspect.studies.learning.tables import (
    ABLATION_OBSTACLES,
    NEEDS,
    OTHER_SHAPES,
    SECTIONS,
    load_evaluations,
    reproduction_sections,
    table1_evaluations,
)

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "docs" / "data" / "rl"
CHECKPOINTS = ROOT / "bench" / "checkpoints" / "rl"
DOC = ROOT / "docs" / "reproduction.md"
BATCHES = ROOT / "bench" / ".rl-batches"
LEARNING_CODE = ROOT / "src" / "seminspect" / "missions" / "learning"
PICTURE = ROOT / "docs" / "images" / "rl-coverage.png"
TRAINING_PICTURE = ROOT / "docs" / "images" / "rl-training.png"
#: The training logs kept beside the evaluations (copies of each run's progress.csv).
TRAINING_LOGS = {
    "main (shipped)": DATA / "training-main.csv",
    "no SVS map": DATA / "training-no-svs.csv",
    "no GRU": DATA / "training-no-gru.csv",
}
SEED, EPISODES, ENVS = 0, 100, 50

Source = Callable[[], Controller] | Path
#: Evaluation file -> (baseline factory or checkpoint file, obstacle counts, policy label,
#: object shape).
EVALUATIONS: dict[str, tuple[Source, tuple[int, ...], str, TargetShape]] = {
    "table1-learned": (shipped_policy_path(), TABLE1_OBSTACLES, "learned (shipped)", "cylinder"),
    "table1-orbit": (OrbitController, TABLE1_OBSTACLES, "orbit", "cylinder"),
    "table1-random": (lambda: RandomController(SEED), TABLE1_OBSTACLES, "random", "cylinder"),
    "ablation-no-svs": (CHECKPOINTS / "no-svs.pt", (ABLATION_OBSTACLES,), "no SVS map", "cylinder"),
    "ablation-no-gru": (CHECKPOINTS / "no-gru.pt", (ABLATION_OBSTACLES,), "no GRU", "cylinder"),
}
#: The runs in the paper's rooms (directories under CHECKPOINTS), by the label of their rows.
RETRAINED_RUNS = {
    "v2-main": "v2 (5.0 M steps)",
    "v2-main-2m": "v2 (2.0 M steps)",
    "v2-no-svs": "v2, no SVS map (2.0 M steps)",
    "v2-no-gru": "v2, no GRU (2.0 M steps)",
    "v3-main": "v3 (5.0 M steps)",
    "v3-no-svs": "v3, no SVS map (2.0 M steps)",
    "v3-no-gru": "v3, no GRU (2.0 M steps)",
    "v3-gru-512": "v3, GRU 512 (2.0 M steps)",
    "v4-tune": "v4: v3 fine-tuned with the contact penalty (1.0 M steps)",
    "v4-main": "v4 (5.0 M steps)",
}
EVALUATIONS |= {
    run: (CHECKPOINTS / run / "checkpoint.pt", (ABLATION_OBSTACLES,), label, "cylinder")
    for run, label in RETRAINED_RUNS.items()
}
for _shape in OTHER_SHAPES:  # the generalisation table: one evaluation per shape
    EVALUATIONS[f"shape-learned-{_shape}"] = (
        shipped_policy_path(),
        (ABLATION_OBSTACLES,),
        "learned (shipped)",
        _shape,
    )
    EVALUATIONS[f"shape-orbit-{_shape}"] = (OrbitController, (ABLATION_OBSTACLES,), "orbit", _shape)


def log(text: str) -> None:
    print(f"[{time.strftime('%H:%M:%S')}] {text}", flush=True)


def code_digest() -> str:
    """SHA-256 of the learning package's source: a batch flown by other code is flown again."""
    digest = hashlib.sha256()
    for path in sorted(LEARNING_CODE.rglob("*.py")):
        digest.update(path.relative_to(LEARNING_CODE).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def run_evaluation(
    name: str, episodes: int, data: Path, only: Sequence[int] | None = None
) -> EvaluationResult:
    """Evaluate one controller (its batches kept in BATCHES) and keep its JSON under ``data``;
    with ``only``, just those obstacle counts, into the store alone."""
    source, counts, label, shape = EVALUATIONS[name]
    controller: Controller
    if isinstance(source, Path):
        controller, digest = load_controller(source), file_sha256(source)
    else:
        controller, digest = source(), None
    identity = {
        "evaluation": name, "checkpoint_sha256": digest, "code": code_digest(),
        "numpy": np.__version__, "torch": torch.__version__,
    }  # fmt: skip
    result = evaluate(
        controller,
        [k for k in counts if only is None or k in only],
        episodes,
        SEED,
        config=controller_evaluation_config(controller, (shape,)),
        num_envs=ENVS,
        policy=label,
        checkpoint_sha256=digest,
        store=BatchStore(BATCHES / name, identity),
    )
    if only is None:
        result.to_json(data / f"{name}.json")
    log(f"{name}: {result.wall_seconds:.0f} s of flying")
    return result


def regenerate(
    wanted: set[str],
    episodes: int = EPISODES,
    names: list[str] | None = None,
    only: Sequence[int] | None = None,
) -> dict[str, str]:
    """Run the evaluations the wanted sections need (or ``names``), then build the sections.

    Returns no sections when an evaluation a section needs has never been run, or when
    ``only`` some obstacle counts were flown (into the store).
    """
    DATA.mkdir(parents=True, exist_ok=True)
    for name in sorted({n for s in wanted for n in NEEDS[s]}) if names is None else names:
        log(f"evaluating {name} ({episodes} episodes per obstacle count)")
        run_evaluation(name, episodes, DATA, only)
    if only is not None:
        log(f"kept the batches of {sorted(only)} obstacles in {BATCHES}; run again without "
            "--obstacles to write the evaluations")  # fmt: skip
        return {}
    results = load_evaluations(DATA)
    missing = sorted({n for s in wanted for n in NEEDS[s]} - set(results))
    if missing:
        log(f"not rewriting the tables: no evaluation yet for {', '.join(missing)}")
        return {}
    if "rl-table1" in wanted:
        save_figure(coverage_figure(table1_evaluations(results)), PICTURE)
        save_figure(training_figure(TRAINING_LOGS), TRAINING_PICTURE)
        log(f"drew {PICTURE} and {TRAINING_PICTURE}")
    return reproduction_sections(results, wanted)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", action="append", choices=SECTIONS, help="(repeatable)")
    parser.add_argument("--episodes", type=int, default=EPISODES, help="per obstacle count")
    parser.add_argument(
        "--evaluation",
        action="append",
        choices=sorted(EVALUATIONS),
        help="run only these evaluations (repeatable; e.g. to spread them over processes)",
    )
    parser.add_argument(
        "--obstacles",
        type=int,
        nargs="+",
        help="fly only these obstacle counts, into the batch store (one process's share)",
    )
    parser.add_argument("--tables-only", action="store_true", help="rewrite from stored JSON")
    parser.add_argument("--doc", type=Path, default=DOC)
    args = parser.parse_args()
    wanted = set(args.only or SECTIONS)
    names = [] if args.tables_only else args.evaluation
    try:
        sections = regenerate(wanted, args.episodes, names, args.obstacles)
        if sections:
            rewrite_sections(args.doc, sections)
    except (FileFormatError, InvalidInputError) as error:
        raise SystemExit(f"error: {error}") from None
    if sections:
        log(f"rewrote {', '.join(sorted(sections))} in {args.doc}; policy: {shipped_policy_path()}")


if __name__ == "__main__":
    main()
