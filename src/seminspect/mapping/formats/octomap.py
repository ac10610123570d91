"""Reading OctoMap ``.bt`` files into a :class:`~seminspect.mapping.voxel.VoxelMap`.

The paper's volumetric baseline plans on an OctoMap (000 Sec VII-C). OctoMap stores a pruned
octree whose leaves are cubes of the tree resolution times a power of two, each free or occupied;
space outside every leaf is unknown. Decoding uses the ``pyoctomap`` bindings of the OctoMap
library (optional extra ``octomap``). The leaves are then painted onto a dense grid of any
resolution: a cell takes the "highest" state of the leaves overlapping it (occupied over free over
unknown), the rule OctoMap itself uses for inner nodes (maximum child occupancy), so an obstacle
is never lost by coarsening.
"""

from __future__ import annotations

import functools
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numba
import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError, InvalidInputError, SeminspectError
from seminspect.mapping.voxel import FREE, OCCUPIED, VoxelMap

_MAGIC = b"# Octomap OcTree binary file"
_HEADER_BYTES = 4096


@dataclass(frozen=True)
class OctreeLeaves:
    """The leaves of an octree: cube centres ``(N, 3)``, edge lengths ``(N,)`` [m], occupancy."""

    centers: NDArray[np.float64]
    sizes: NDArray[np.float64]
    occupied: NDArray[np.bool_]
    resolution: float


def _check_header(source: Path) -> None:
    """Refuse files that are not binary OcTrees before handing them to the C++ reader."""
    try:
        with source.open("rb") as handle:
            head = handle.read(_HEADER_BYTES)
    except FileNotFoundError:
        raise FileFormatError(f"{source}: no such file") from None
    except IsADirectoryError:
        raise FileFormatError(f"{source}: is a directory, expected an OctoMap .bt file") from None
    except OSError as exc:
        raise FileFormatError(f"{source}: cannot read ({exc.strerror})") from None
    if not head.startswith(_MAGIC):
        raise FileFormatError(f"{source}: not an OctoMap binary tree (.bt) file")
    lines = head.split(b"\n")
    if b"id OcTree" not in lines or b"data" not in lines:
        raise FileFormatError(f"{source}: OctoMap header lacks 'id OcTree' or 'data'")


def read_octomap_leaves(path: str | os.PathLike[str]) -> OctreeLeaves:
    """Decode the leaves of a ``.bt`` file with ``pyoctomap``.

    The last files decoded are kept (keyed by path, size and modification time, their arrays
    read-only): a routine site built from a map reads it for the world and for ``M_H``.

    Raises:
        FileFormatError: missing, malformed or truncated file.
        SeminspectError: the ``octomap`` extra is not installed.
    """
    source = Path(path)
    _check_header(source)
    stat = source.stat()
    return _decoded(str(source.resolve()), stat.st_size, stat.st_mtime_ns, str(source))


@functools.lru_cache(maxsize=2)
def _decoded(resolved: str, size: int, mtime_ns: int, shown: str) -> OctreeLeaves:
    """The leaves of one version of a file (``size`` and ``mtime_ns`` tell versions apart)."""
    del size, mtime_ns  # only part of the cache key
    source = Path(shown)
    try:
        import pyoctomap  # noqa: PLC0415 - an optional extra
    except ImportError:
        raise SeminspectError(
            "reading OctoMap files needs the 'octomap' extra: pip install 'seminspect[octomap]'"
        ) from None
    tree = pyoctomap.OcTree(0.1)  # the file's own resolution replaces this
    if not tree.readBinary(resolved):
        raise FileFormatError(f"{source}: malformed or truncated OctoMap data")
    centers, sizes, occupied = [], [], []
    for leaf in tree.begin_leafs():
        centers.append(leaf.getCoordinate())
        sizes.append(leaf.getSize())
        occupied.append(tree.isNodeOccupied(leaf))
    if not centers:
        raise FileFormatError(f"{source}: the OctoMap has no leaves")
    arrays = (
        np.asarray(centers, dtype=np.float64),
        np.asarray(sizes, dtype=np.float64),
        np.asarray(occupied, dtype=bool),
    )
    for array in arrays:
        array.flags.writeable = False  # shared by every caller of the cache
    return OctreeLeaves(*arrays, float(tree.getResolution()))


@numba.njit(cache=True)
def _paint(
    states: NDArray[np.uint8],
    lower: NDArray[np.int64],
    upper: NDArray[np.int64],
    values: NDArray[np.uint8],
) -> None:
    for n in range(values.shape[0]):
        value = values[n]
        for i in range(lower[n, 0], upper[n, 0]):
            for j in range(lower[n, 1], upper[n, 1]):
                for k in range(lower[n, 2], upper[n, 2]):
                    states[i, j, k] = max(states[i, j, k], value)


def voxel_map_from_leaves(leaves: OctreeLeaves, resolution: float | None = None) -> VoxelMap:
    """A dense map covering the leaves' bounding box at ``resolution`` (default: the tree's)."""
    res = leaves.resolution if resolution is None else float(resolution)
    if not (math.isfinite(res) and res > 0):
        raise InvalidInputError(f"resolution must be > 0, got {resolution!r}")
    half = leaves.sizes[:, None] / 2
    low, high = leaves.centers - half, leaves.centers + half
    # OctoMap keeps coordinates in float32: a tolerance of a thousandth of a cell keeps a leaf
    # that ends on a cell boundary out of the next cell.
    grid = VoxelMap.empty(low.min(axis=0), high.max(axis=0) - 1e-3 * res, res)
    lower = np.floor((low - grid.origin) / res + 1e-3).astype(np.int64)
    upper = np.ceil((high - grid.origin) / res - 1e-3).astype(np.int64)
    upper = np.clip(np.maximum(upper, lower + 1), 0, np.asarray(grid.shape))
    lower = np.clip(lower, 0, np.asarray(grid.shape))
    values = np.where(leaves.occupied, OCCUPIED, FREE).astype(np.uint8)
    _paint(grid.states, lower, upper, values)
    return grid


def load_octomap(path: str | os.PathLike[str], resolution: float | None = None) -> VoxelMap:
    """Load a ``.bt`` OctoMap as a dense free / occupied / unknown map at ``resolution``."""
    return voxel_map_from_leaves(read_octomap_leaves(path), resolution)
