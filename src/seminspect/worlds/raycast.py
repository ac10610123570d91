"""First-hit ray casting against a world mesh with Embree.

Embree traces rays in single precision. The scene is shifted so that the world's centre sits at
the origin, which keeps metre-scale worlds far inside float32's precision. Asking Embree for the
hit distance ``tfar`` costs nothing extra, so the caster returns distances directly instead of
intersecting rays with triangle planes afterwards. Rays go through a compiled loop over Embree's
C API (``worlds.embree``) that writes only the distance and face of each ray; ``embreex``'s own
loop is the fallback where its library cannot be loaded, with the same hits.
"""

from __future__ import annotations

from functools import partial
from typing import NamedTuple

import numpy as np
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh
from numpy.typing import ArrayLike, NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.core.threads import run_dealt
from seminspect.worlds.embree import MAX_TFAR, EmbreeScene, cast_rays, embree_library

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
        shifted = (verts - self.offset).astype(np.float32)
        library = embree_library()
        if library is not None:
            self._compiled: EmbreeScene | None = EmbreeScene(library, shifted, tris)
        else:
            self._compiled = None
            self._scene = rtcore_scene.EmbreeScene()
            TriangleMesh(scene=self._scene, vertices=shifted, indices=tris.astype(np.int32))

    def cast(
        self,
        origins: ArrayLike,
        directions: ArrayLike,
        max_range: float | ArrayLike = np.inf,
        threads: int = 1,
        *,
        out: tuple[NDArray[np.float32], NDArray[np.int32]] | None = None,
    ) -> tuple[NDArray[np.float32], NDArray[np.int32]]:
        """Distance to and index of the first triangle hit by each ray.

        Args:
            origins: ``(N, 3)`` ray origins, or one ``(3,)`` origin shared by every ray.
            directions: ``(N, 3)`` unit directions (not normalised here: distances are in
                units of the direction's length).
            max_range: ignore hits farther than this, one value or one per ray.
            threads: split the rays over this many threads (Embree releases the GIL, so
                large batches scale with cores; results do not depend on the split).
            out: ``(distance, face)`` arrays of ``N`` ``float32`` and ``int32`` to write into,
                e.g. buffers reused between frames (returned).

        Returns:
            ``(distance, face)``: ``float32`` distances (``inf`` for no hit within range) and
            ``int32`` face indices (``-1`` for no hit).
        """
        dirs = np.asarray(directions, dtype=np.float32)
        if dirs.ndim != 2 or dirs.shape[1] != 3:
            raise InvalidInputError(f"ray directions must have shape (N, 3), got {dirs.shape}")
        count = dirs.shape[0]
        start = np.asarray(origins, dtype=np.float64) - self.offset
        if start.shape not in ((3,), (count, 3)):
            raise InvalidInputError(f"ray origins must be (3,) or ({count}, 3), got {start.shape}")
        starts = start.astype(np.float32).reshape(-1, 3)
        limit = np.ascontiguousarray(max_range, dtype=np.float32).reshape(-1)
        if limit.shape[0] not in (1, count):
            raise InvalidInputError(f"max_range must be one value or {count}, got {limit.shape}")
        distance, face = _outputs(count, out)
        batch = _Batch(starts, dirs, limit, distance, face)
        cast_part = self._cast_compiled if self._compiled is not None else self._cast_embreex
        run_dealt(partial(cast_part, batch), count, threads, MIN_RAYS_PER_THREAD)
        return batch.distance, batch.face

    def _cast_compiled(self, batch: _Batch, part: slice) -> None:
        scene = self._compiled
        assert scene is not None
        cast_rays(
            scene.intersect,
            scene.scene,
            batch.starts if len(batch.starts) == 1 else batch.starts[part],
            np.ascontiguousarray(batch.directions[part]),
            batch.limits if len(batch.limits) == 1 else batch.limits[part],
            batch.distance[part],
            batch.face[part],
        )

    def _cast_embreex(self, batch: _Batch, part: slice) -> None:
        count = len(batch.directions)
        hits = self._scene.run(
            np.broadcast_to(batch.starts, (count, 3))[part],
            np.ascontiguousarray(batch.directions[part]),
            dists=np.minimum(np.broadcast_to(batch.limits, (count,))[part], MAX_TFAR),
            output=1,
        )
        batch.face[part] = hits["primID"]
        batch.distance[part] = np.where(hits["primID"] == NO_HIT, np.inf, hits["tfar"])


class _Batch(NamedTuple):
    """One call's rays (origins shifted, ``float32``) and the outputs its parts fill."""

    starts: NDArray[np.float32]  # (N, 3), or (1, 3) shared
    directions: NDArray[np.float32]  # (N, 3)
    limits: NDArray[np.float32]  # (N,), or (1,) shared
    distance: NDArray[np.float32]
    face: NDArray[np.int32]


def _outputs(
    count: int, out: tuple[NDArray, NDArray] | None
) -> tuple[NDArray[np.float32], NDArray[np.int32]]:
    if out is None:
        return np.empty(count, np.float32), np.empty(count, np.int32)
    distance, face = out
    for array, dtype in ((distance, np.float32), (face, np.int32)):
        if array.shape != (count,) or array.dtype != dtype or not array.flags.c_contiguous:
            raise InvalidInputError(f"cast outputs must be contiguous ({count},) {dtype.__name__}")
    return distance, face
