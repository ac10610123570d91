"""Hierarchical query time versus graph size, against flat Dijkstra on the same queries.

For synthetic 3DLSGs of 20 to 10,000 inspected vehicles (one level of ~20 view poses each, a
few features per pose), random queries "go to feature F" start from a random point near the
graph. Each query is answered by

* the hierarchical planner (localise, Target-layer A*, two local searches, waypoints);
* flat Dijkstra over the whole traversable graph with the same compiled kernel, which isolates
  what the hierarchy buys;
* networkx Dijkstra over the same flat graph, the usual library baseline (fewer queries on big
  graphs: it takes about a second each at 10,000 targets).

Every flat answer is checked to cost the same as the hierarchical one.

Run: ``.venv/bin/python bench/graph_planning.py`` (add ``--json out.json`` to keep the figures).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import networkx as nx
import numpy as np

from seminspect.graphs.lsg.networkx_view import traversable_networkx
from seminspect.graphs.lsg.synthetic import synthetic_graph
from seminspect.planning.graph_astar import CsrGraph, shortest_path
from seminspect.planning.hierarchical import HierarchicalPlanner
from seminspect.studies.xflie.scaling import random_queries


def flat_csr(flat: nx.Graph) -> tuple[CsrGraph, dict[str, int]]:
    index = {node: i for i, node in enumerate(flat.nodes)}
    coords = np.array([flat.nodes[n]["pos"] for n in flat.nodes])
    edges = [(index[a], index[b]) for a, b in flat.edges]
    weights = [w for _, _, w in flat.edges(data="weight")]
    return CsrGraph.from_edges(coords, edges, weights), index


def percentiles(seconds: list[float]) -> tuple[float, float]:
    micro = np.asarray(seconds) * 1e6
    return float(np.percentile(micro, 50)), float(np.percentile(micro, 95))


def run_size(n_targets: int, n_queries: int, nx_queries: int, seed: int) -> dict[str, float]:
    t0 = time.perf_counter()
    graph = synthetic_graph(n_targets, seed=seed)
    build_s = time.perf_counter() - t0
    planner = HierarchicalPlanner(graph)
    t0 = time.perf_counter()
    planner.localise([0.0, 0.0, 0.0])  # builds the search index once
    index_s = time.perf_counter() - t0
    flat = traversable_networkx(graph)
    csr, flat_index = flat_csr(flat)
    queries = random_queries(graph, n_queries, seed + 1)

    hier, target_layer, flat_kernel, nx_times, settled = [], [], [], [], []
    for k, (start, goal) in enumerate(queries):
        t0 = time.perf_counter()
        plan = planner.plan(goal, start)
        hier.append(time.perf_counter() - t0)
        target_layer.append(plan.timing.target_layer_s)
        settled.append(plan.settled)
        source, sink = flat_index[plan.localisation.node_id], flat_index[plan.node_path[-1]]
        t0 = time.perf_counter()
        cost, _, _ = shortest_path(csr, source, sink, heuristic=False)
        flat_kernel.append(time.perf_counter() - t0)
        if abs(cost - plan.cost) > 1e-6 * max(1.0, cost):
            raise AssertionError(f"flat Dijkstra disagrees on query {k}: {cost} vs {plan.cost}")
        if k < nx_queries:
            t0 = time.perf_counter()
            reference = nx.dijkstra_path_length(flat, plan.localisation.node_id, plan.node_path[-1])
            nx_times.append(time.perf_counter() - t0)
            if abs(reference - plan.cost) > 1e-6 * max(1.0, reference):
                raise AssertionError(f"networkx disagrees on query {k}")
    stats = graph.population()
    h50, h95 = percentiles(hier)
    f50, f95 = percentiles(flat_kernel)
    n50, _ = percentiles(nx_times)
    t50, _ = percentiles(target_layer)
    return {
        "targets": n_targets,
        "unified_nodes": stats.unified.nodes,
        "flat_nodes": flat.number_of_nodes(),
        "build_s": build_s,
        "index_s": index_s,
        "hier_p50_us": h50,
        "hier_p95_us": h95,
        "target_layer_p50_us": t50,
        "settled_median": float(np.median(settled)),
        "flat_kernel_p50_us": f50,
        "flat_kernel_p95_us": f95,
        "flat_networkx_p50_us": n50,
        "speedup_vs_flat_kernel": f50 / h50,
        "speedup_vs_networkx": n50 / h50,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[20, 100, 1000, 10000])
    parser.add_argument("--queries", type=int, default=400)
    parser.add_argument("--nx-queries", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", help="also write the figures to this JSON file")
    args = parser.parse_args()

    header = (
        f"{'targets':>8} {'nodes':>8} {'hier p50':>9} {'hier p95':>9} {'T-layer':>8} "
        f"{'settled':>8} {'flat p50':>9} {'nx p50':>10} {'x flat':>7} {'x nx':>8}"
    )
    print("hierarchical vs flat shortest paths (times in microseconds, same queries)")
    print(header)
    rows = []
    for size in args.sizes:
        row = run_size(size, args.queries, args.nx_queries, args.seed)
        rows.append(row)
        print(
            f"{row['targets']:>8} {row['unified_nodes']:>8} {row['hier_p50_us']:>9.1f} "
            f"{row['hier_p95_us']:>9.1f} {row['target_layer_p50_us']:>8.1f} "
            f"{row['settled_median']:>8.0f} {row['flat_kernel_p50_us']:>9.1f} "
            f"{row['flat_networkx_p50_us']:>10.0f} {row['speedup_vs_flat_kernel']:>7.1f} "
            f"{row['speedup_vs_networkx']:>8.0f}"
        )
    print("nodes: unified graph; T-layer: Target-layer search; settled: nodes the query touched;")
    print("flat: Dijkstra over the whole traversable graph, same compiled kernel; nx: networkx")
    for row in rows:
        print(
            f"  {row['targets']:>6} targets: graph built in {row['build_s']:.2f} s, "
            f"search index in {row['index_s'] * 1e3:.1f} ms"
        )
    if args.json:
        with Path(args.json).open("w", encoding="utf-8") as handle:
            json.dump(rows, handle, indent=2)


if __name__ == "__main__":
    main()
