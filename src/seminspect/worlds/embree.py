"""Embree's C API called from compiled code, on the library that ``embreex`` ships.

``embreex`` traces one ray per call of ``rtcIntersect1`` inside a compiled loop, but to return
both the distance and the face of each ray it hands back six fresh arrays per batch
(barycentrics, normals, ids), which a frame paid for on every call. Here the same scene is
built through the same C calls (``rtcNewGeometry`` with a copied float3 vertex and uint3 index
buffer, a robust scene: ``embreex``'s defaults), and a numba kernel calls ``rtcIntersect1`` for
each ray and writes only the distance and the face, so the hits are the library's own, bit for
bit (``tests/worlds/test_embree.py`` compares them with ``embreex``).

Where the shared library cannot be found (a build of ``embreex`` that links Embree some other
way), :func:`embree_library` returns ``None`` and callers use ``embreex``'s own loop.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import weakref
from functools import cache
from pathlib import Path

import embreex
import numba
import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic
from numpy.typing import NDArray

from seminspect.core.errors import SeminspectError

# Values of Embree 4's enums (rtcore_common.h, rtcore_buffer.h, rtcore_geometry.h,
# rtcore_scene.h).
_GEOMETRY_TYPE_TRIANGLE = 0
_BUFFER_TYPE_INDEX = 0
_BUFFER_TYPE_VERTEX = 1
_FORMAT_UINT3 = 0x5003
_FORMAT_FLOAT3 = 0x9003
_SCENE_FLAG_ROBUST = 1 << 2
_INVALID_ID = 0xFFFFFFFF

#: Farthest distance handed to Embree: larger limits (``inf``) are clamped to it.
MAX_TFAR = np.float32(1e30)
#: 32-bit words of one ``RTCRayHit`` (48-byte ray, 32-byte hit), and the word offsets used.
RAYHIT_WORDS = 20
_TFAR, _MASK, _PRIM_ID, _GEOM_ID = 8, 9, 17, 18


class EmbreeError(SeminspectError):
    """Embree refused to build a scene."""


@cache
def embree_library() -> ctypes.CDLL | None:
    """Embree 4 as loaded by ``embreex`` (the wheel's bundled copy, else the system's)."""
    package = Path(embreex.__file__).parent
    places = (package.parent / "embreex.libs", package / ".dylibs", package)
    found = [path for place in places for path in sorted(place.glob("*embree4*"))]
    name = str(found[0]) if found else ctypes.util.find_library("embree4")
    if name is None:
        return None
    try:
        library = ctypes.CDLL(name)
    except OSError:
        return None
    _declare(library)
    return library


def _declare(library: ctypes.CDLL) -> None:
    pointer, uint, size, enum = ctypes.c_void_p, ctypes.c_uint, ctypes.c_size_t, ctypes.c_int
    signatures = {
        "rtcNewDevice": ([ctypes.c_char_p], pointer),
        "rtcGetDeviceError": ([pointer], enum),
        "rtcReleaseDevice": ([pointer], None),
        "rtcNewScene": ([pointer], pointer),
        "rtcSetSceneFlags": ([pointer, enum], None),
        "rtcCommitScene": ([pointer], None),
        "rtcReleaseScene": ([pointer], None),
        "rtcNewGeometry": ([pointer, enum], pointer),
        "rtcSetNewGeometryBuffer": ([pointer, enum, uint, enum, size, size], pointer),
        "rtcCommitGeometry": ([pointer], None),
        "rtcAttachGeometry": ([pointer, pointer], uint),
        "rtcReleaseGeometry": ([pointer], None),
    }
    for name, (arguments, result) in signatures.items():
        function = getattr(library, name)
        function.argtypes, function.restype = arguments, result


class EmbreeScene:
    """One committed triangle mesh in its own Embree device.

    Args:
        library: from :func:`embree_library`.
        vertices: ``(V, 3) float32`` vertices.
        faces: ``(F, 3)`` vertex indices.
    """

    def __init__(self, library: ctypes.CDLL, vertices: NDArray, faces: NDArray) -> None:
        address = ctypes.cast(library.rtcIntersect1, ctypes.c_void_p).value
        if address is None:
            raise EmbreeError("Embree's rtcIntersect1 has no address")
        self.intersect: int = address
        device = library.rtcNewDevice(None)
        if not device:
            raise EmbreeError("Embree could not create a device")
        scene = library.rtcNewScene(device)
        self._finalizer = weakref.finalize(self, _release, library, device, scene)
        library.rtcSetSceneFlags(scene, _SCENE_FLAG_ROBUST)
        geometry = library.rtcNewGeometry(device, _GEOMETRY_TYPE_TRIANGLE)
        _fill(library, geometry, vertices, kind=_BUFFER_TYPE_VERTEX, dtype=np.float32, stride=4)
        _fill(library, geometry, faces, kind=_BUFFER_TYPE_INDEX, dtype=np.uint32, stride=3)
        library.rtcCommitGeometry(geometry)
        library.rtcAttachGeometry(scene, geometry)
        library.rtcReleaseGeometry(geometry)
        library.rtcCommitScene(scene)
        error = library.rtcGetDeviceError(device)
        if error:
            raise EmbreeError(f"Embree failed to build the scene (error {error})")
        self.scene = scene


def _fill(
    library: ctypes.CDLL,
    geometry: int,
    rows: NDArray,
    *,
    kind: int,
    dtype: type[np.generic],
    stride: int,
) -> None:
    """Copy ``(n, 3)`` ``rows`` into a new geometry buffer of ``stride`` items per row."""
    layout = _FORMAT_FLOAT3 if kind == _BUFFER_TYPE_VERTEX else _FORMAT_UINT3
    address = library.rtcSetNewGeometryBuffer(
        geometry, kind, 0, layout, stride * np.dtype(dtype).itemsize, len(rows)
    )
    if not address:
        raise EmbreeError("Embree could not allocate a geometry buffer")
    items = (ctypes.c_byte * (len(rows) * stride * np.dtype(dtype).itemsize)).from_address(address)
    view = np.frombuffer(memoryview(items), dtype=dtype).reshape(len(rows), stride)
    view[:, :3] = rows


def _release(library: ctypes.CDLL, device: int, scene: int) -> None:
    library.rtcReleaseScene(scene)
    library.rtcReleaseDevice(device)


@intrinsic
def _intersect1(typingctx, function, scene, rayhit):
    """``rtcIntersect1(scene, rayhit, NULL)`` through the function's address."""
    signature = types.void(types.intp, types.intp, rayhit)

    def codegen(context, builder, sig, args):
        address, scene_address, words = args
        byte_pointer = ir.IntType(8).as_pointer()
        callee_type = ir.FunctionType(ir.VoidType(), [byte_pointer] * 3)
        callee = builder.inttoptr(address, callee_type.as_pointer())
        data = context.make_array(sig.args[2])(context, builder, words).data
        builder.call(
            callee,
            [
                builder.inttoptr(scene_address, byte_pointer),
                builder.bitcast(data, byte_pointer),
                ir.Constant(byte_pointer, None),
            ],
        )
        return context.get_dummy_value()

    return signature, codegen


@numba.njit(cache=True, nogil=True)
def cast_rays(  # noqa: PLR0917 - a compiled kernel takes its arrays positionally
    function: int,
    scene: int,
    origins: np.ndarray,
    directions: np.ndarray,
    limits: np.ndarray,
    distance: np.ndarray,
    face: np.ndarray,
) -> None:
    """First hits of rays ``[0, len(directions))`` into ``distance`` and ``face``.

    ``origins`` is ``(N, 3)`` or one ``(1, 3)`` row shared by every ray, ``limits`` ``(N,)``
    or one shared value (clamped to :data:`MAX_TFAR`); all ``float32``, origins in the scene's
    (shifted) frame. Misses get ``inf`` and ``-1``.
    """
    # Embree wants the ray 16-byte aligned; twice its size leaves slack for a wider RTCHit.
    block = np.zeros(2 * RAYHIT_WORDS + 4, dtype=np.uint32)
    skip = (-block.ctypes.data) % 16 // 4
    words = block[skip : skip + 2 * RAYHIT_WORDS]
    rayhit = words.view(np.float32)
    shared_origin = origins.shape[0] == 1
    shared_limit = limits.shape[0] == 1
    for i in range(directions.shape[0]):
        row = 0 if shared_origin else i
        rayhit[0] = origins[row, 0]
        rayhit[1] = origins[row, 1]
        rayhit[2] = origins[row, 2]
        rayhit[3] = 0.0  # tnear
        rayhit[4] = directions[i, 0]
        rayhit[5] = directions[i, 1]
        rayhit[6] = directions[i, 2]
        rayhit[7] = 0.0  # time
        rayhit[_TFAR] = min(limits[0] if shared_limit else limits[i], MAX_TFAR)
        words[_MASK] = _INVALID_ID  # every mask bit
        words[10] = 0  # id
        words[11] = 0  # flags
        words[_PRIM_ID] = _INVALID_ID
        words[_GEOM_ID] = _INVALID_ID
        words[19] = _INVALID_ID  # instID[0]
        _intersect1(function, scene, words)  # type: ignore[call-arg]  # numba passes typingctx
        if words[_PRIM_ID] == _INVALID_ID:
            distance[i] = np.inf
            face[i] = -1
        else:
            distance[i] = rayhit[_TFAR]
            face[i] = np.int32(words[_PRIM_ID])
