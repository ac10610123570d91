"""Strategies shared by the 3DLSG and planner property tests."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.synthetic import synthetic_graph


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
