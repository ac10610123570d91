"""Views of a 3DLSG as networkx graphs: the whole unified graph, one layer, or the traversable
part."""

from __future__ import annotations

import networkx as nx
import numpy as np

from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.model import (
    EdgeKind,
    FeatureNode,
    Layer,
    LevelNode,
    Node,
    PoseNode,
    RobotNode,
    TargetNode,
)
from seminspect.graphs.lsg.structure import GraphStructure
from seminspect.graphs.lsg.tables import Row, edge_row, node_row


def node_attributes(node: Node) -> dict[str, str | float | int | bool]:
    """Flat, GraphML-friendly attributes of a node (vectors split into scalar fields)."""
    attrs: dict[str, str | float | int | bool] = {
        "layer": node.layer.value,
        "kind": type(node).__name__,
    }
    attrs.update(zip(("x", "y", "z"), (float(c) for c in node.position), strict=True))
    if isinstance(node, RobotNode | PoseNode):
        attrs.update(
            zip(("qx", "qy", "qz", "qw"), (float(c) for c in node.orientation), strict=True)
        )
    if isinstance(node, TargetNode):
        attrs.update(
            label=node.label,
            status=node.status.value,
            score=node.score,
            mask_area=node.mask_area,
            utility=node.utility,
            observations=node.observations,
        )
    if isinstance(node, FeatureNode):
        attrs.update(label=node.label, score=node.score, mask_area=node.mask_area)
    if isinstance(node, LevelNode | PoseNode | FeatureNode):
        attrs["name"] = node.name
    image = getattr(node, "image", None)
    if image:
        attrs["image"] = image
    return attrs


def to_networkx(graph: LayeredSemanticGraph) -> nx.Graph:
    """The unified graph ``G_k`` with flat attributes on every node and edge."""
    result = nx.Graph()
    for node in graph.nodes():
        result.add_node(node.id, **node_attributes(node))
    for edge in graph.edges():
        result.add_edge(edge.u, edge.v, kind=edge.kind.value, weight=float(edge.weight))
    return result


def layer_networkx(graph: GraphStructure, layer: Layer) -> nx.Graph:
    """One layer as the union of its local graphs, parents included (the Pose layer holds the
    levels and their poses), so it has the nodes and edges ``graph.population()`` counts for
    that layer. Node attributes are the node's table row (:mod:`.tables`, ``layer`` added);
    edge attributes are ``kind``, ``weight`` and ``via_points``."""
    result = nx.Graph(layer=layer.value)
    for local in graph.local_graphs(layer):
        for node in local.nodes.values():
            result.add_node(node.id, layer=node.layer.value, **_without_id(node_row(node)))
        for edge in local.edges.values():
            row = edge_row(edge)
            result.add_edge(row.pop("u"), row.pop("v"), **row)
    return result


def _without_id(row: Row) -> Row:
    return {key: value for key, value in row.items() if key != "id"}


def traversable_networkx(graph: LayeredSemanticGraph) -> nx.Graph:
    """The flattened traversable graph: levels and poses of inspected targets, their spatial
    edges, and each ``v_I - v_I`` edge attached to the two targets' ``Level-0`` nodes.

    This is the reference a flat Dijkstra search runs on; the hierarchical planner must find
    the same costs.
    """
    result = nx.Graph()
    entries: dict[str, str] = {}
    for target in graph.targets():
        if not (target.inspected and target.levels):
            continue
        entries[target.id] = LayeredSemanticGraph.entry_level(target).id
        local_graphs = [target.level_graph, *(level.pose_graph for level in target.levels)]
        for local in local_graphs:
            assert local is not None
            for node in local.nodes.values():
                if isinstance(node, LevelNode | PoseNode):
                    result.add_node(node.id, pos=np.asarray(node.position))
            for edge in local.edges.values():
                if edge.kind is EdgeKind.SPATIAL:
                    result.add_edge(edge.u, edge.v, weight=edge.weight)
    for edge in graph.target_graph.edges.values():
        if edge.kind is EdgeKind.SPATIAL and edge.u in entries and edge.v in entries:
            result.add_edge(entries[edge.u], entries[edge.v], weight=edge.weight)
    return result
