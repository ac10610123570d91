"""Regenerate the example graph shipped in ``src/seminspect/data/example_graph.json``.

Run: ``.venv/bin/python scripts/make_example_graph.py``. The output is deterministic.
"""

from pathlib import Path

from seminspect.graphs.lsg.io import save_graph
from seminspect.graphs.lsg.synthetic import synthetic_graph

OUT = Path(__file__).resolve().parents[1] / "src" / "seminspect" / "data" / "example_graph.json"

if __name__ == "__main__":
    graph = synthetic_graph(5, seed=0, levels=2, poses_per_level=12, parts_per_pose=2)
    save_graph(graph, OUT)
    print(f"wrote {OUT} ({OUT.stat().st_size} bytes)")
