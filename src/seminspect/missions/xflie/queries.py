"""The operator's queries at the end of a mission, planned over the final graph and driven
(000 Sec V-C semantic navigation)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from seminspect.core.errors import SeminspectError
from seminspect.missions.xflie import XFlie
from seminspect.missions.xflie.metrics import QueryAnswer


def answer_queries(mission: XFlie, queries: Sequence[str]) -> list[QueryAnswer]:
    """Plan each query over the final graph and drive it (000 Sec V-C semantic navigation)."""
    answers = []
    epsilon = mission.params.epsilon
    for text in queries:
        try:
            plan = mission.planner.query(text, start=mission.platform.position)
        except SeminspectError as exc:
            answers.append(QueryAnswer(text, None, None, None, False, None, str(exc)))
            continue
        driven = mission.navigator.drive(plan.waypoints, plan.final_yaw)
        if not driven:
            driven = mission.navigator.go_to(
                plan.waypoints[-1], radius=0.5, final_yaw=plan.final_yaw
            )
        goal = mission.graph.node(plan.node_path[-1]).position
        distance = float(np.linalg.norm(mission.platform.position - goal))
        answers.append(
            QueryAnswer(
                text, plan.goal_id, plan.timing.total_s, plan.length, distance <= epsilon, distance
            )
        )
        mission.recorder.plan(plan.goal_id, plan)
    return answers
