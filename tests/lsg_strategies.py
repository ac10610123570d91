"""Strategies shared by the 3DLSG and planner property tests."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
from hypothesis import strategies as st

from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.synthetic import synthetic_graph
from seminspect.perception.observation import Observation


@st.composite
def layered_graphs(draw: st.DrawFn) -> LayeredSemanticGraph:
    """Varied, fully inspected graphs, some Target-layer edges realised through via points."""
    graph = synthetic_graph(
        draw(st.integers(1, 6)),
        seed=draw(st.integers(0, 2**16)),
        poses_per_level=draw(st.integers(1, 7)),
        levels=draw(st.integers(1, 3)),
        parts_per_pose=draw(st.integers(0, 3)),
        spacing=draw(st.floats(9.0, 30.0)),
        neighbours=draw(st.integers(0, 3)),
    )
    targets = graph.targets()
    for _ in range(draw(st.integers(0, 3))):
        a, b = draw(st.sampled_from(targets)), draw(st.sampled_from(targets))
        if a is not b and graph.edge(a.id, b.id) is None:
            via = np.asarray(draw(st.lists(st.tuples(*[st.floats(-50, 150)] * 3), max_size=3)))
            graph.connect_targets(a.id, b.id, via.reshape(-1, 3))
    return graph


@st.composite
def climbing_graphs(draw: st.DrawFn) -> LayeredSemanticGraph:
    """Inspected multi-level targets whose rings may be left open and whose level edges may be
    realised through via points (as a mission builds them when it cannot drive them straight)."""
    coordinate = st.floats(-20, 20)
    graph = LayeredSemanticGraph(robot_position=(0.0, 0.0, 0.0))
    count = draw(st.integers(1, 3))
    for k in range(count):
        graph.register_target(Observation([40.0 * k, 0, 1], label="building", mask_area=1))
    graph.optimise_targets()
    for k, target in enumerate(graph.targets()):
        centre = np.array([40.0 * k, 0.0, 0.0])
        for level in range(draw(st.integers(1, 3))):
            start = centre + np.array([draw(coordinate), draw(coordinate), 2.0 + 3.0 * level])
            if level == 0:
                graph.begin_inspection(target.id, Observation.view_pose(start))
            else:
                via = draw(st.lists(st.tuples(coordinate, coordinate, coordinate), max_size=3))
                route = centre + np.asarray(via).reshape(-1, 3) if via else None
                graph.begin_level(Observation.view_pose(start), via=route)
            for _ in range(draw(st.integers(1, 5))):
                offset = [draw(coordinate), draw(coordinate), 0.0]
                graph.register_pose(Observation.view_pose(start + offset))
            graph.close_level(close_ring=draw(st.booleans()))
        graph.finish_inspection()
    targets = graph.targets()
    for a, b in pairwise(targets):
        graph.connect_targets(a.id, b.id)
    return graph
