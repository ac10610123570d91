"""Site pairs for routine inspection (002): the world as first mapped and as it is today.

Each pair is a *historical* world, from which the map ``M_H`` is recorded and on which the
inspection regions are drawn, and a *current* world the robot inspects later. For the mine
drift of :mod:`~seminspect.worlds.underground` (same rock for one seed) the scenarios are:

* ``nominal``: nothing changed (002 Figs 7-8).
* ``receding``: a block stood against the face when ``M_H`` was recorded and is gone now, so
  the surface lies 1.0-1.5 m (seeded) further away (002 Fig 10: objects removed after mapping).
* ``advancing``: the whole face has moved 0.5-1.5 m (seeded) towards the portal.
* ``obstructed``: a rockfall, floor to roof over two thirds of the drift's width, lies across the
  historical route between a wall region and the face region; a 2 m gap remains.

Every pair carries a default task set: named, flat polygons ``(K, 3)`` on the historical
surface. A user pair comes from two labelled meshes and has no default tasks.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError
from seminspect.core.names import unknown_name
from seminspect.core.rng import make_rng
from seminspect.worlds.shapes import box
from seminspect.worlds.underground import DRIFT_WIDTH, drift_world
from seminspect.worlds.user import load_world
from seminspect.worlds.world import World

SCENARIOS = ("nominal", "receding", "advancing", "obstructed")
#: Drift length for routine scenarios [m]: long enough for a route, short enough for CI.
DEFAULT_LENGTH = 20.0
RECEDING_DEPTH_M = (1.0, 1.5)
ADVANCE_M = (0.5, 1.5)
#: The face region: across the middle of the drift, 0.8-2.4 m up.
FACE_SPAN_Y = (1.3, 3.7)
REGION_SPAN_Z = (0.8, 2.4)
ROCKFALL_GAP_M = 2.0


@dataclass(frozen=True)
class SitePair:
    """A historical and a current world with the default inspection regions of the site.

    Attributes:
        change: what differs, as numbers a report can print (kind and size).
        tasks: ``(name, vertices (K, 3))`` polygons on the historical surface.
    """

    name: str
    seed: int
    historical: World
    current: World
    change: dict[str, Any]
    tasks: tuple[tuple[str, NDArray[np.float64]], ...] = field(default=())


def face_region(x: float) -> NDArray[np.float64]:
    """The default face polygon on the plane ``x``."""
    (y0, y1), (z0, z1) = FACE_SPAN_Y, REGION_SPAN_Z
    return np.array([[x, y0, z0], [x, y1, z0], [x, y1, z1], [x, y0, z1]])


def wall_region(x0: float, x1: float) -> NDArray[np.float64]:
    """A polygon on the drift's right-hand wall (``y = 0``) between ``x0`` and ``x1``."""
    z0, z1 = REGION_SPAN_Z
    return np.array([[x0, 0.0, z0], [x1, 0.0, z0], [x1, 0.0, z1], [x0, 0.0, z1]])


def mine_drift_site(scenario: str, seed: int, length: float = DEFAULT_LENGTH) -> SitePair:
    """The ``scenario`` pair of the mine drift for ``seed`` (module docstring)."""
    if scenario not in SCENARIOS:
        raise unknown_name("routine scenario", scenario, SCENARIOS)
    rng = make_rng(seed, "worlds", "routine", scenario)
    plain = drift_world(seed, length)
    if scenario == "nominal":
        return SitePair(
            scenario, seed, plain, plain, {"kind": "none"}, (("face", face_region(length)),)
        )
    if scenario == "receding":
        depth = float(rng.uniform(*RECEDING_DEPTH_M))
        block = box(
            (length - depth, FACE_SPAN_Y[0] - 0.4, 0.0),
            (length + 0.3, FACE_SPAN_Y[1] + 0.4, 3.0),
            "rock",
        )
        historical = drift_world(seed, length, rocks=[block])
        change = {"kind": "receding", "depth_m": depth}
        return SitePair(
            scenario, seed, historical, plain, change, (("face", face_region(length - depth)),)
        )
    if scenario == "advancing":
        advance = float(rng.uniform(*ADVANCE_M))
        current = drift_world(seed, length, face_advance=advance)
        change = {"kind": "advancing", "advance_m": advance}
        return SitePair(scenario, seed, plain, current, change, (("face", face_region(length)),))
    x = 0.6 * length
    rockfall = box((x, -0.2, 0.0), (x + 1.2, DRIFT_WIDTH - ROCKFALL_GAP_M, 4.5), "rock")
    current = drift_world(seed, length, rocks=[rockfall])
    change = {"kind": "obstructed", "rockfall_x_m": [x, x + 1.2], "gap_m": ROCKFALL_GAP_M}
    tasks = (("wall", wall_region(0.25 * length, 0.4 * length)), ("face", face_region(length)))
    return SitePair(scenario, seed, plain, current, change, tasks)


def world_files(directory: str | os.PathLike[str]) -> tuple[Path, Path]:
    """The ``(mesh, labels)`` files of a world directory: ``world.<mesh format>`` beside
    ``labels.json`` (or ``.yaml``/``.yml``), as ``seminspect world export`` writes them."""
    root = Path(directory)
    if not root.is_dir():
        raise InvalidInputError(f"{root} is not a directory with world.<mesh> and labels.json")
    labels = [
        p for p in (root / f"labels{ext}" for ext in (".json", ".yaml", ".yml")) if p.exists()
    ]
    meshes = sorted(p for p in root.glob("world.*") if p.suffix.lower() != ".json")
    if len(labels) != 1 or len(meshes) != 1:
        raise InvalidInputError(
            f"{root} must hold one world.<mesh> and one labels.json/.yaml; found "
            f"{[p.name for p in meshes + labels] or 'neither'}"
        )
    return meshes[0], labels[0]


def user_site(
    historical: tuple[str | os.PathLike[str], str | os.PathLike[str]],
    current: tuple[str | os.PathLike[str], str | os.PathLike[str]],
) -> SitePair:
    """A pair from two ``(mesh, labels)`` files (see :func:`~seminspect.worlds.load_world`);
    it has no default tasks, so a task file must name the regions."""
    before, after = load_world(*historical), load_world(*current)
    if not np.allclose(before.start_position, after.start_position):
        raise InvalidInputError("the historical and current worlds must share a start position")
    return SitePair("user", 0, before, after, {"kind": "user"})
