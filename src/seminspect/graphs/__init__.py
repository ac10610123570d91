"""Scene graphs: the 3D Layered Semantic Graph (``lsg``) and outdoor task graphs (``terrain``)."""

from seminspect.graphs import lsg, terrain

__all__ = ["lsg", "terrain"]
