"""Running a mission end to end and leaving a complete run directory behind.

:func:`run_mission` builds the world, the simulated robot and the executive
(:mod:`.build`), runs it, answers the operator's queries (:mod:`.queries`), scores the result
against the world's ground truth (:mod:`.figures`) and writes everything to the run directory
(:mod:`.outputs`); a team's run is :mod:`.team_run`. A Ctrl-C, a SIGTERM or a failure
mid-mission still writes the graph and metrics gathered so far and records why the run
stopped; every file is written atomically, and the last status is written after every output,
so it never claims a file that is not there.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence

from seminspect.core.interrupts import stop_on_signals
from seminspect.missions.xflie import MissionProgress
from seminspect.missions.xflie.build import build_mission, run_name
from seminspect.missions.xflie.config import (
    MissionConfig,
    ResolvedMissionConfig,
    default_scenario,
    resolve,
)
from seminspect.missions.xflie.figures import mission_metrics
from seminspect.missions.xflie.layout import OUTPUT_FILES, XFLIE_LAYOUT
from seminspect.missions.xflie.live import LiveWatch, refuse_unwatchable
from seminspect.missions.xflie.metrics import CpuMeter, MissionMetrics, QueryAnswer
from seminspect.missions.xflie.outputs import MissionResult, save_outputs, write_graph_first
from seminspect.missions.xflie.queries import answer_queries
from seminspect.missions.xflie.team_run import run_team
from seminspect.planning.routes import warm_up
from seminspect.runs.conduct import RunEnd, conduct_run
from seminspect.runs.directory import RunDirectory
from seminspect.sensors import Detector
from seminspect.worlds import World, open_world


def run_mission(
    config: MissionConfig,
    out: str | os.PathLike[str] | None = None,
    *,
    base: str | os.PathLike[str] = "runs",
    queries: Sequence[str] = (),
    progress: Callable[[MissionProgress], None] | None = None,
    detector: Detector | None = None,
    watch: LiveWatch | None = None,
) -> MissionResult:
    """Run a mission into ``out`` (default: a fresh directory under ``base``), every robot
    seeing through ``detector`` (default: the simulator's labels with the fault model), shown
    live to ``watch`` when given (one robot only: a team is refused).

    The world is made first, so a bad world or scenario creates no directory. ``out`` is then
    claimed (see :meth:`RunDirectory.claimed`): a second run on it fails at once, and files of an
    earlier run in it are removed. Ctrl-C and SIGTERM end the mission as ``interrupted``.
    """
    if watch is not None:
        refuse_unwatchable(config)
    world = open_world(config.world, default_scenario(config), seed=config.seed)
    config = resolve(config, world)
    with stop_on_signals():
        run = (
            RunDirectory(out, XFLIE_LAYOUT)
            if out is not None
            else RunDirectory.fresh(base, run_name(config), XFLIE_LAYOUT)
        )
        with run.claimed(config.model_dump(mode="json")):
            if config.robots:
                return run_team(run, config, world, queries, progress, detector=detector)
            return _run(run, config, world, queries, progress, detector=detector, watch=watch)


def _run(
    run: RunDirectory,
    config: ResolvedMissionConfig,
    world: World,
    queries: Sequence[str],
    progress: Callable[[MissionProgress], None] | None,
    *,
    detector: Detector | None,
    watch: LiveWatch | None,
) -> MissionResult:
    mission, world = build_mission(config, run, progress, world, detector=detector)
    if watch is not None:
        watch.attach(mission, world)
    warm_up()  # compile before the clock starts: a fresh install times plans, not numba
    cpu = CpuMeter()
    answers: list[QueryAnswer] = []
    metrics: MissionMetrics | None = None

    def write_outputs(end: RunEnd) -> None:
        nonlocal answers, metrics
        write_graph_first(run, mission.graph)
        answers = answer_queries(mission, queries) if end.state == "completed" else []
        metrics = mission_metrics(
            mission, world, cpu, state=end.state, reason=end.reason, answers=answers
        )
        save_outputs(run, mission, metrics, answers)

    end = conduct_run(run, mission.execute, write_outputs, expected=OUTPUT_FILES, what="mission")
    if watch is not None:
        watch.publish(ended=end.state)
    return MissionResult(
        run.root, end.state, end.reason, metrics, mission, world, answers, end.signum
    )
