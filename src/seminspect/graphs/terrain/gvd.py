"""Terrain-aware place nodes from a generalized Voronoi diagram on a 2D grid (001 Sec III-B.3).

For one terrain type, on a boolean grid (True = the terrain is there):

1. dilation then erosion (closing) and erosion then dilation (opening) remove misidentified
   cells, and patches below a minimum area are dropped;
2. a brushfire distance map gives every terrain cell its distance to, and its nearest, non-terrain
   cell (the exact Euclidean brushfire of Lau et al. [51], computed by
   ``scipy.ndimage.distance_transform_edt``);
3. the GVD is Lau et al.'s Voronoi test: two neighbouring cells whose nearest obstacle cells are
   not adjacent lie on either side of a bisector, and the one closer to it is a Voronoi cell;
4. pruning thins the Voronoi cells to one-cell-wide lines (``skimage.morphology.thin``) and cuts
   spurs shorter than a length, which small bumps in the patch outline create;
5. nodes go to junctions (cells with three or more of their 8 neighbours on the GVD, one node per
   touching group) and corners (dead ends; see ``docs/terrain.md`` for this reading), never two
   orthogonally adjacent;
6. refinement repeats, until nothing changes or an iteration cap: a flood fill along the GVD gives
   every cell to its closest node and links nodes whose cells touch; on each link the chain cell
   deviating most from the straight line between the two nodes becomes a node if it deviates
   more than a threshold, else the chain's midpoint becomes one if the nodes are farther apart
   than a length threshold (after Hydra [14]).

Grid coordinates are ``(row, col)`` cell indices; the caller maps them to metres.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage, sparse
from scipy.sparse.csgraph import dijkstra
from skimage.morphology import thin

_EIGHT = np.ones((3, 3), dtype=bool)
_RING = np.array([[1, 1, 1], [1, 0, 1], [1, 1, 1]])
#: Lau et al. call two nearest-obstacle cells distinct when they are not adjacent (gap > 1).
#: The exact EDT's nearest cells jump by two along digitised concave borders, which made spurious
#: Voronoi cells there; a gap of more than two cells keeps only true bisectors.
_OBSTACLE_GAP = 2
#: Forward neighbour offsets; with their reverses they are the 8-neighbourhood.
_FORWARD = ((0, 1), (1, 0), (1, 1), (1, -1))


@dataclass
class GvdResult:
    """The GVD of one terrain type, with every intermediate stage (001 Fig 3).

    Attributes:
        occupancy: the raw terrain grid (Fig 3a).
        cleaned: after dilation/erosion and small-patch removal.
        distance: brushfire distance to the nearest non-terrain cell, in cells (Fig 3b).
        voronoi: cells passing the Voronoi test, before pruning.
        skeleton: the pruned, one-cell-wide GVD (Fig 3c, 3d).
        initial_nodes: ``(K0, 2)`` junction and corner cells (Fig 3c).
        nodes: ``(K, 2)`` node cells after refinement (Fig 3d).
        edges: ``(a, b, length_in_cells)`` links between node indices.
        owner: node index owning each GVD cell after the last flood fill, -1 elsewhere.
        iterations: refinement iterations run.
    """

    occupancy: NDArray[np.bool_]
    cleaned: NDArray[np.bool_]
    distance: NDArray[np.float64]
    voronoi: NDArray[np.bool_]
    skeleton: NDArray[np.bool_]
    initial_nodes: NDArray[np.int64]
    nodes: NDArray[np.int64]
    edges: list[tuple[int, int, float]] = field(default_factory=list)
    owner: NDArray[np.int64] = field(default_factory=lambda: np.zeros((0, 0), np.int64))
    iterations: int = 0


def clean_grid(
    occupancy: NDArray[np.bool_], smoothing_cells: int, min_patch_cells: int
) -> NDArray[np.bool_]:
    """Closing then opening with a disc of ``smoothing_cells``, then drop small patches."""
    grid = occupancy.astype(bool)
    if smoothing_cells > 0:
        radius = smoothing_cells
        yy, xx = np.mgrid[-radius : radius + 1, -radius : radius + 1]
        disc = xx * xx + yy * yy <= radius * radius
        # pad so that closing cannot invent terrain along the grid border
        padded = np.pad(grid, radius + 1)
        padded = ndimage.binary_closing(padded, structure=disc)
        padded = ndimage.binary_opening(padded, structure=disc)
        grid = padded[radius + 1 : -radius - 1, radius + 1 : -radius - 1]
    labels, count = ndimage.label(grid, structure=_EIGHT)
    if count == 0:
        return grid
    sizes = np.bincount(labels.ravel(), minlength=count + 1)
    keep = sizes >= max(min_patch_cells, 1)
    keep[0] = False
    return keep[labels]


def distance_map(free: NDArray[np.bool_]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Brushfire distance (cells) from each terrain cell to the nearest non-terrain cell.

    Returns the distances and the ``(2, H, W)`` indices of that nearest obstacle cell. Cells past
    the grid border count as obstacles.
    """
    padded = np.pad(free, 1)
    distance, nearest = ndimage.distance_transform_edt(padded, return_indices=True)
    return distance[1:-1, 1:-1], nearest[:, 1:-1, 1:-1] - 1


def voronoi_cells(
    free: NDArray[np.bool_], distance: NDArray[np.float64], nearest: NDArray[np.int64]
) -> NDArray[np.bool_]:
    """Lau et al.'s Voronoi test on every pair of 4-neighbours (vectorised)."""
    index = np.indices(free.shape)
    rows, cols = index[0, :, :], index[1, :, :]
    near_rows: NDArray[np.int64] = nearest[0, :, :]
    near_cols: NDArray[np.int64] = nearest[1, :, :]
    squared = np.rint(distance**2).astype(np.int64)
    voronoi = np.zeros(free.shape, dtype=bool)
    for axis in (0, 1):
        here = [slice(None), slice(None)]
        there = [slice(None), slice(None)]
        here[axis], there[axis] = slice(None, -1), slice(1, None)
        s, n = tuple(here), tuple(there)
        obst_s = (near_rows[s], near_cols[s])
        obst_n = (near_rows[n], near_cols[n])
        gap = np.maximum(np.abs(obst_s[0] - obst_n[0]), np.abs(obst_s[1] - obst_n[1]))
        apart = gap > _OBSTACLE_GAP
        candidate = free[s] & free[n] & ((squared[s] > 1) | (squared[n] > 1)) & apart
        # how much farther the neighbour's obstacle is from each cell than its own obstacle
        stability_s = (rows[s] - obst_n[0]) ** 2 + (cols[s] - obst_n[1]) ** 2 - squared[s]
        stability_n = (rows[n] - obst_s[0]) ** 2 + (cols[n] - obst_s[1]) ** 2 - squared[n]
        candidate &= (stability_s >= 0) & (stability_n >= 0)
        voronoi[s] |= candidate & (stability_s <= stability_n) & (squared[s] > 2)
        voronoi[n] |= candidate & (stability_n <= stability_s) & (squared[n] > 2)
    return voronoi


def neighbour_count(cells: NDArray[np.bool_]) -> NDArray[np.int64]:
    """How many of each cell's 8 neighbours are set."""
    return ndimage.convolve(cells.astype(np.int64), _RING, mode="constant")


def _drop_fragments(
    skeleton: NDArray[np.bool_], terrain: NDArray[np.bool_], min_cells: int
) -> NDArray[np.bool_]:
    labels, count = ndimage.label(skeleton, structure=_EIGHT)
    if count < 2:
        return skeleton
    sizes = np.bincount(labels.ravel(), minlength=count + 1)
    patches, _ = ndimage.label(terrain, structure=_EIGHT)
    # the patch of each GVD component, and the largest component of each patch
    patch_of = np.zeros(count + 1, dtype=np.int64)
    patch_of[labels[skeleton]] = patches[skeleton]
    largest = np.zeros(int(patches.max()) + 1, dtype=np.int64)
    np.maximum.at(largest, patch_of[1:], sizes[1:])
    keep = (sizes >= min_cells) | (sizes == largest[patch_of])
    keep[0] = False
    return keep[labels]


def prune(
    voronoi: NDArray[np.bool_], terrain: NDArray[np.bool_], min_branch_cells: int
) -> NDArray[np.bool_]:
    """Thin to one-cell-wide lines and cut spurs and fragments shorter than ``min_branch_cells``.

    A spur is a dead-end branch hanging off a junction; a fragment is a whole GVD component that
    short, kept only where it is the sole GVD of its terrain patch.
    """
    skeleton = _drop_fragments(thin(voronoi), terrain, min_branch_cells)
    for _ in range(4):  # cutting a spur can leave a shorter one behind at the same junction
        counts = neighbour_count(skeleton) * skeleton
        junction = skeleton & (counts >= 3)
        branches = skeleton & ~junction
        labels, count = ndimage.label(branches, structure=_EIGHT)
        if count == 0:
            break
        sizes = np.bincount(labels.ravel(), minlength=count + 1)
        at_junction = np.zeros(count + 1, dtype=bool)
        at_junction[labels[ndimage.binary_dilation(junction, _EIGHT) & branches]] = True
        dead_end = np.zeros(count + 1, dtype=bool)
        dead_end[labels[skeleton & (counts == 1)]] = True
        spur = at_junction & dead_end & (sizes < min_branch_cells)
        spur[0] = False
        if not spur.any():
            break
        skeleton = thin(skeleton & ~spur[labels])
    return skeleton


@dataclass
class _CellGraph:
    cells: NDArray[np.int64]  # (M, 2)
    index: NDArray[np.int64]  # (H, W), -1 off the mask
    adjacency: sparse.csr_matrix
    pairs: NDArray[np.int64]  # (E, 2) neighbouring cell indices
    weights: NDArray[np.float64]  # (E,)


def cell_graph(mask: NDArray[np.bool_]) -> _CellGraph:
    """The 8-connected graph of a mask's cells, with Euclidean step lengths."""
    cells = np.argwhere(mask)
    index = np.full(mask.shape, -1, dtype=np.int64)
    index[cells[:, 0], cells[:, 1]] = np.arange(cells.shape[0])
    pairs, weights = [], []
    height, width = mask.shape
    for dr, dc in _FORWARD:
        target = cells + np.array([dr, dc])
        ok = (target[:, 0] >= 0) & (target[:, 0] < height) & (target[:, 1] >= 0)
        ok &= target[:, 1] < width
        source = np.flatnonzero(ok)
        other = index[target[ok, 0], target[ok, 1]]
        hit = other >= 0
        pairs.append(np.column_stack([source[hit], other[hit]]))
        weights.append(np.full(int(hit.sum()), float(np.hypot(dr, dc))))
    pair_array = np.concatenate(pairs) if pairs else np.zeros((0, 2), np.int64)
    weight_array = np.concatenate(weights) if weights else np.zeros(0)
    size = cells.shape[0]
    adjacency = sparse.coo_matrix(
        (weight_array, (pair_array[:, 0], pair_array[:, 1])), shape=(size, size)
    ).tocsr()
    return _CellGraph(cells, index, adjacency, pair_array, weight_array)


def flood_fill(
    graph: _CellGraph, sources: NDArray[np.int64]
) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.int64]]:
    """Geodesic distance to, predecessor towards and index of each cell's closest source cell."""
    if sources.size == 0 or graph.cells.shape[0] == 0:
        size = graph.cells.shape[0]
        return np.full(size, np.inf), np.full(size, -9999), np.full(size, -1)
    dist, pred, nearest = dijkstra(
        graph.adjacency,
        directed=False,
        indices=sources,
        min_only=True,
        return_predecessors=True,
    )
    owner = np.full(graph.cells.shape[0], -1, dtype=np.int64)
    reached = nearest >= 0
    order = np.full(graph.cells.shape[0], -1, dtype=np.int64)
    order[sources] = np.arange(sources.size)
    owner[reached] = order[nearest[reached]]
    return dist, pred, owner


def _near(marked: NDArray[np.bool_], row: int, col: int) -> bool:
    """Whether a marked cell lies in the 3x3 window around ``(row, col)``."""
    return bool(marked[max(row - 1, 0) : row + 2, max(col - 1, 0) : col + 2].any())


def initial_nodes(skeleton: NDArray[np.bool_], distance: NDArray[np.float64]) -> list[int]:
    """Junction and corner cells of a pruned GVD, as flat cell indices of the grid."""
    counts = neighbour_count(skeleton) * skeleton
    junction = skeleton & (counts >= 3)
    labels, count = ndimage.label(junction, structure=_EIGHT)
    chosen = np.zeros(skeleton.shape, dtype=bool)
    if count:
        # one node per touching group of junction cells: its cell farthest from the border
        peaks = ndimage.maximum_position(distance, labels, np.arange(1, count + 1))
        for row, col in peaks:
            chosen[int(row), int(col)] = True
    for row, col in np.argwhere(skeleton & (counts <= 1)):
        if not _near(chosen, row, col):
            chosen[row, col] = True
    return list(np.flatnonzero(chosen))


def _seed_loops(
    skeleton: NDArray[np.bool_], distance: NDArray[np.float64], nodes: list[int]
) -> list[int]:
    """Closed GVD loops have neither junctions nor corners: give each two opposite nodes."""
    labels, count = ndimage.label(skeleton, structure=_EIGHT)
    covered = set(labels.ravel()[nodes].tolist()) if nodes else set()
    seeds = []
    for label in range(1, count + 1):
        if label in covered:
            continue
        loop = labels == label
        first = int(np.argmax(np.where(loop, distance, -1.0)))
        seeds.append(first)
        graph = cell_graph(loop)
        start = graph.index.ravel()[first]
        dist, _, _ = flood_fill(graph, np.array([start]))
        far = graph.cells[int(np.argmax(np.where(np.isfinite(dist), dist, -1.0)))]
        if dist.max() > 1.5:
            seeds.append(int(np.ravel_multi_index(tuple(far), skeleton.shape)))
    return seeds


def _links(
    graph: _CellGraph, dist: NDArray[np.float64], owner: NDArray[np.int64]
) -> dict[tuple[int, int], tuple[float, int, int]]:
    """Nodes whose flood-fill regions touch: shortest joining chain ``(length, u, v)``."""
    u, v = graph.pairs[:, 0], graph.pairs[:, 1]
    touching = (owner[u] >= 0) & (owner[v] >= 0) & (owner[u] != owner[v])
    links: dict[tuple[int, int], tuple[float, int, int]] = {}
    for a, b, w in zip(u[touching], v[touching], graph.weights[touching], strict=True):
        cost = float(dist[a] + w + dist[b])
        oa, ob = int(owner[a]), int(owner[b])
        key, ends = ((oa, ob), (int(a), int(b))) if oa < ob else ((ob, oa), (int(b), int(a)))
        if key not in links or cost < links[key][0]:
            links[key] = (cost, *ends)
    return links


def _walk(pred: NDArray[np.int64], cell: int) -> list[int]:
    path = [cell]
    while pred[path[-1]] >= 0:
        path.append(int(pred[path[-1]]))
    return path


def _split_cell(chain: NDArray[np.float64], deviation: float, length: float) -> int | None:
    """Index in ``chain`` of the cell to turn into a node, if the link must be split."""
    start, end = chain[0], chain[-1]
    span = end - start
    norm2 = float(span @ span)
    if chain.shape[0] < 3:
        return None
    t = np.clip(((chain - start) @ span) / norm2, 0.0, 1.0) if norm2 > 0 else np.zeros(len(chain))
    off = np.linalg.norm(chain - (start + t[:, None] * span), axis=1)
    worst = int(np.argmax(off))
    if off[worst] > deviation:
        return worst
    if np.sqrt(norm2) > length:
        steps = np.linalg.norm(np.diff(chain, axis=0), axis=1)
        arc = np.concatenate([[0.0], np.cumsum(steps)])
        middle = int(np.argmin(np.abs(arc - arc[-1] / 2.0)))
        return middle if 0 < middle < chain.shape[0] - 1 else None
    return None


def refine(
    skeleton: NDArray[np.bool_],
    nodes: list[int],
    deviation_cells: float,
    length_cells: float,
    max_iterations: int,
) -> tuple[list[int], list[tuple[int, int, float]], NDArray[np.int64], int]:
    """Flood fill + edge splitting until no node is added or the cap is reached.

    Returns the node cells (flat grid indices), the links, the owner grid and the iterations run.
    """
    graph = cell_graph(skeleton)
    node_list = list(nodes)
    iterations = 0
    while True:
        sources = graph.index.ravel()[np.asarray(node_list, dtype=np.int64)]
        dist, pred, owner = flood_fill(graph, sources)
        links = _links(graph, dist, owner)
        if iterations >= max_iterations:
            break
        taken = np.zeros(skeleton.shape, dtype=bool)
        taken.ravel()[node_list] = True
        added = []
        for _, u, v in links.values():
            chain = _walk(pred, u)[::-1] + _walk(pred, v)
            pick = _split_cell(graph.cells[chain].astype(float), deviation_cells, length_cells)
            if pick is None:
                continue
            row, col = graph.cells[chain[pick]]
            if _near(taken, row, col):
                continue
            taken[row, col] = True
            added.append(int(np.ravel_multi_index((row, col), skeleton.shape)))
        iterations += 1
        if not added:
            break
        node_list.extend(added)
    owner_grid = np.full(skeleton.shape, -1, dtype=np.int64)
    owner_grid[graph.cells[:, 0], graph.cells[:, 1]] = owner
    edges = [(a, b, length) for (a, b), (length, _, _) in sorted(links.items())]
    return node_list, edges, owner_grid, iterations


def build_gvd(
    occupancy: NDArray[np.bool_],
    *,
    smoothing_cells: int,
    min_patch_cells: int,
    min_branch_cells: int,
    deviation_cells: float,
    length_cells: float,
    max_iterations: int,
) -> GvdResult:
    """All of 001 Sec III-B.3 for one terrain grid (lengths in cells)."""
    cleaned = clean_grid(occupancy, smoothing_cells, min_patch_cells)
    distance, nearest = distance_map(cleaned)
    voronoi = voronoi_cells(cleaned, distance, nearest)
    skeleton = prune(voronoi, cleaned, min_branch_cells)
    start = initial_nodes(skeleton, distance)
    start += _seed_loops(skeleton, distance, start)
    nodes, edges, owner, iterations = refine(
        skeleton, start, deviation_cells, length_cells, max_iterations
    )

    def cells(flat: list[int]) -> NDArray[np.int64]:
        if not flat:
            return np.zeros((0, 2), dtype=np.int64)
        return np.column_stack(np.unravel_index(np.asarray(flat), skeleton.shape)).astype(np.int64)

    return GvdResult(
        occupancy=occupancy.astype(bool),
        cleaned=cleaned,
        distance=distance,
        voronoi=voronoi,
        skeleton=skeleton,
        initial_nodes=cells(start),
        nodes=cells(nodes),
        edges=edges,
        owner=owner,
        iterations=iterations,
    )
