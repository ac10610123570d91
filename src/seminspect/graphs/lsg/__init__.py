"""The 3D Layered Semantic Graph of 000 Sec IV: Target -> Level -> Pose -> Feature."""

from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.io import (
    example_graph_path,
    export_graphml,
    export_spark_dsg,
    load_graph,
    save_graph,
)
from seminspect.graphs.lsg.model import (
    Edge,
    EdgeKind,
    FeatureNode,
    Layer,
    LevelNode,
    PoseNode,
    RobotNode,
    TargetNode,
    TargetStatus,
)
from seminspect.graphs.lsg.networkx_view import layer_networkx, to_networkx, traversable_networkx
from seminspect.graphs.lsg.population import PopulationStats
from seminspect.graphs.lsg.structure import GraphStructure
from seminspect.graphs.lsg.synthetic import synthetic_graph
from seminspect.graphs.lsg.tables import export_csv, layer_edge_rows, layer_rows

__all__ = [
    "Edge",
    "EdgeKind",
    "FeatureNode",
    "GraphStructure",
    "Layer",
    "LayeredSemanticGraph",
    "LevelNode",
    "PopulationStats",
    "PoseNode",
    "RobotNode",
    "TargetNode",
    "TargetStatus",
    "example_graph_path",
    "export_csv",
    "export_graphml",
    "export_spark_dsg",
    "layer_edge_rows",
    "layer_networkx",
    "layer_rows",
    "load_graph",
    "save_graph",
    "synthetic_graph",
    "to_networkx",
    "traversable_networkx",
]
