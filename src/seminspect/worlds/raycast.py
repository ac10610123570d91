"""First-hit ray casting against a world mesh with Embree.

Embree (through ``embreex``) traces rays in single precision. The scene is shifted so that the
world's centre sits at the origin, which keeps metre-scale worlds far inside float32's precision.
Asking Embree for the hit distance ``tfar`` costs nothing extra, so the caster returns distances
directly instead of intersecting rays with triangle planes afterwards.
"""

from __future__ import annotations

import itertools
from concurrent.futures import ThreadPoolExecutor
from functools import cache

import numpy as np
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError

#: Embree's "no hit" primitive id.
NO_HIT = -1
#: Below this many rays per thread, splitting a batch costs more than it saves.
MIN_RAYS_PER_THREAD = 4096


class RayCaster:
    """Cached Embree scene of one triangle mesh.

    Args:
        vertices: ``(V, 3)`` mesh vertices (metres).
        faces: ``(F, 3)`` triangle vertex indices.
    """

    def __init__(self, vertices: ArrayLike, faces: ArrayLike) -> None:
        verts = np.asarray(vertices, dtype=np.float64)
        tris = np.asarray(faces)
        if verts.ndim != 2 or verts.shape[1] != 3 or tris.ndim != 2 or tris.shape[1] != 3:
            raise InvalidInputError("ray caster needs (V, 3) vertices and (F, 3) faces")
        if len(tris) == 0:
            raise InvalidInputError("ray caster needs at least one triangle")
        self.offset = 0.5 * (verts.min(axis=0) + verts.max(axis=0))
        self.face_count = len(tris)
        self._scene = rtcore_scene.EmbreeScene()
        TriangleMesh(
            scene=self._scene,
            vertices=(verts - self.offset).astype(np.float32),
            indices=tris.astype(np.int32),
        )

    def cast(
        self,
        origins: ArrayLike,
        directions: ArrayLike,
        max_range: float | ArrayLike = np.inf,
        threads: int = 1,
    ) -> tuple[NDArray[np.float32], NDArray[np.int32]]:
        """Distance to and index of the first triangle hit by each ray.

        Args:
            origins: ``(N, 3)`` ray origins, or one ``(3,)`` origin shared by every ray.
            directions: ``(N, 3)`` unit directions (not normalised here: distances are in
                units of the direction's length).
            max_range: ignore hits farther than this, one value or one per ray.
            threads: split the rays over this many threads (Embree releases the GIL, so
                large batches scale with cores; results do not depend on the split).

        Returns:
            ``(distance, face)``: ``float32`` distances (``inf`` for no hit within range) and
            ``int32`` face indices (``-1`` for no hit).
        """
        dirs = np.ascontiguousarray(directions, dtype=np.float32)
        if dirs.ndim != 2 or dirs.shape[1] != 3:
            raise InvalidInputError(f"ray directions must have shape (N, 3), got {dirs.shape}")
        count = dirs.shape[0]
        start = np.asarray(origins, dtype=np.float64) - self.offset
        if start.shape == (3,):
            # Embree reads through strides, so one shared origin needs no copy per ray.
            start32 = np.broadcast_to(start.astype(np.float32), (count, 3))
        elif start.shape == (count, 3):
            start32 = start.astype(np.float32)
        else:
            raise InvalidInputError(f"ray origins must be (3,) or ({count}, 3), got {start.shape}")
        limit = np.broadcast_to(np.asarray(max_range, dtype=np.float32), (count,))
        limit = np.ascontiguousarray(np.minimum(limit, np.float32(1e30)))
        face, distance = self._run(start32, dirs, limit, threads)
        distance[face == NO_HIT] = np.inf
        return distance, face

    def _run(
        self, starts: NDArray, dirs: NDArray, limit: NDArray, threads: int
    ) -> tuple[NDArray[np.int32], NDArray[np.float32]]:
        if threads <= 1 or len(dirs) < 2 * MIN_RAYS_PER_THREAD:
            hits = self._scene.run(starts, dirs, dists=limit, output=1)
            return hits["primID"], hits["tfar"]
        bounds = np.linspace(0, len(dirs), threads + 1).astype(int)
        parts = [slice(a, b) for a, b in itertools.pairwise(bounds)]
        hits = list(
            _pool(threads).map(
                lambda part: self._scene.run(starts[part], dirs[part], dists=limit[part], output=1),
                parts,
            )
        )
        face = np.concatenate([h["primID"] for h in hits])
        distance = np.concatenate([h["tfar"] for h in hits])
        return face, distance


@cache
def _pool(threads: int) -> ThreadPoolExecutor:
    return ThreadPoolExecutor(threads, thread_name_prefix="embree")
