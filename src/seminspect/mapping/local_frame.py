"""Units and a local origin for point files in survey coordinates (feet, UTM).

A point file may be in metres, international feet (0.3048 m) or US survey feet (1200/3937 m),
and in projected coordinates of millions of metres (UTM northings ~5e6 m), where float32 keeps
only half a metre. :func:`to_local_frame` converts to metres and subtracts a local origin before
anything else; the :class:`LocalFrame` it returns maps results back:
``file_coordinates = (local + origin_m) / metres_per_unit``.

The origin is the floor, to whole metres, of the cloud's minimum corner, and only when some
coordinate lies farther than :data:`LARGE_COORDINATE` from zero: a cloud already in a local
frame (a robot's map, the simulator's) keeps its coordinates exactly.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError

#: Metres per unit of the units ``--units`` takes.
METRES_PER_UNIT: dict[str, float] = {"m": 1.0, "ft": 0.3048, "us-ft": 1200 / 3937}
#: Coordinates farther than this from zero [m] make the cloud move to a local origin.
LARGE_COORDINATE = 10_000.0


@dataclass(frozen=True)
class LocalFrame:
    """How a file's coordinates became the local metric frame the graph is built in."""

    units: str
    vertical_units: str
    units_from: str
    origin_m: tuple[float, float, float]

    @property
    def metres_per_unit(self) -> tuple[float, float, float]:
        horizontal = METRES_PER_UNIT[self.units]
        return horizontal, horizontal, METRES_PER_UNIT[self.vertical_units]

    def to_json(self) -> dict[str, Any]:
        return {
            "units": self.units,
            "vertical_units": self.vertical_units,
            "units_from": self.units_from,
            "metres_per_unit": list(self.metres_per_unit),
            "origin_m": list(self.origin_m),
            "to_file": "file = (local + origin_m) / metres_per_unit",
        }


def check_units(units: str | None) -> str | None:
    """``units`` if ``--units`` knows it, else one line listing the choices."""
    if units is not None and units not in METRES_PER_UNIT:
        choices = ", ".join(METRES_PER_UNIT)
        raise InvalidInputError(f"--units must be one of {choices}, got {units!r}")
    return units


def choose_units(
    requested: str | None, declared: str | None, declared_vertical: str | None, declared_from: str
) -> tuple[str, str, str]:
    """Horizontal and vertical units and where they came from: ``--units`` wins, then the
    file's header, then metres."""
    if requested is not None:
        return requested, requested, "from --units"
    if declared is not None:
        return declared, declared_vertical or declared, f"from the file's header, {declared_from}"
    return "m", "m", "no units declared: metres assumed"


def to_local_frame(
    points: NDArray[np.float64], units: str, vertical_units: str, units_from: str
) -> tuple[NDArray[np.float64], LocalFrame]:
    """The points in metres about a local origin, and the frame that maps them back."""
    horizontal = METRES_PER_UNIT[units]
    scale = np.array([horizontal, horizontal, METRES_PER_UNIT[vertical_units]])
    metres = np.asarray(points, dtype=np.float64) * scale
    origin = np.zeros(3)
    if metres.size and float(np.abs(metres).max()) > LARGE_COORDINATE:
        origin = np.floor(metres.min(axis=0))
        metres -= origin
    frame = LocalFrame(units, vertical_units, units_from, tuple(float(v) for v in origin))  # type: ignore[arg-type]
    return metres, frame
