"""ASPRS LAS and LAZ point files (airborne and mobile LiDAR), read with laspy.

Coordinates are the header's scaled values (``X * scale + offset``) as float64, in the file's
own units; the linear unit the header declares (GeoTIFF key 3076 ``ProjLinearUnitsGeoKey``, or
the last length ``UNIT`` of an OGC WKT record) comes with them, so callers can convert to metres
(:mod:`seminspect.mapping.local_frame`). The ASPRS classification is kept beside the points, not
taken as labels: the point of this reader is unlabelled data, and the classes serve as ground
truth (or as labels when the user asks for them, :func:`classification_labels`).

LAZ needs laspy's ``lazrs`` backend (the ``laz`` extra).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError

#: GeoTIFF unit codes (EPSG unit of measure) of the linear units a LAS header may declare.
GEOTIFF_UNITS: dict[int, str] = {9001: "m", 9002: "ft", 9003: "us-ft"}
#: GeoTIFF keys of the projected linear unit and of the vertical unit (GeoTIFF 1.0 sec 6.2).
PROJ_LINEAR_UNITS_KEY = 3076
VERTICAL_UNITS_KEY = 4099
#: ASPRS standard classes (LAS 1.4 R15 table 17) as label names; never-classified,
#: unclassified and noise carry no semantics (``mapping.ingest.UNLABELLED``).
ASPRS_CLASSES: dict[int, str] = {
    0: "unlabelled", 1: "unlabelled", 2: "ground", 3: "low vegetation",
    4: "medium vegetation", 5: "high vegetation", 6: "building", 7: "outlier",
    9: "water", 10: "rail", 11: "road", 13: "wire", 14: "wire", 15: "tower",
    17: "bridge", 18: "outlier",
}  # fmt: skip
_WKT_UNIT = re.compile(r'(?:LENGTHUNIT|UNIT)\s*\[\s*"([^"]+)"\s*,\s*([0-9.eE+-]+)')
_ANGULAR = ("degree", "radian", "grad", "arc")


@dataclass
class LasPointData:
    """A LAS file's points with its classification and declared units.

    It has the fields of :class:`~seminspect.mapping.formats.pointfiles.PointData` (LAS files
    carry no labels or embeddings, so those are empty), and is not its subclass only because
    ``pointfiles`` dispatches to this module. ``unit`` is ``"m"``, ``"ft"``, ``"us-ft"`` or
    ``None`` (the header says nothing); ``unit_source`` says where it was read (e.g.
    ``"GeoTIFF key 3076"``).
    """

    points: NDArray[np.float64]
    embeddings: NDArray[np.float32] | None = None
    labels: NDArray[np.int64] | None = None
    label_names: dict[int, str] = field(default_factory=dict)
    classification: NDArray[np.uint8] | None = None
    unit: str | None = None
    vertical_unit: str | None = None
    unit_source: str = ""


def read_las(path: str | Path) -> LasPointData:
    """Read a ``.las`` or ``.laz`` file: float64 scaled coordinates, classes, declared units."""
    source = Path(path)
    if not source.is_file():
        raise FileFormatError(f"{source}: no such file")
    las = _open(source)
    points = np.column_stack([np.asarray(las.x), np.asarray(las.y), np.asarray(las.z)])
    if points.shape[0] == 0:
        raise FileFormatError(f"{source}: the file holds no points")
    if not np.all(np.isfinite(points)):
        raise FileFormatError(f"{source}: the header's scale or offset makes non-finite points")
    unit, vertical, unit_source = header_units(las.header)
    return LasPointData(
        points.astype(np.float64),
        classification=np.asarray(las.classification, dtype=np.uint8),
        unit=unit,
        vertical_unit=vertical,
        unit_source=unit_source,
    )


def _open(source: Path):
    import laspy  # noqa: PLC0415 - imported with the first LAS file, not with the package
    from laspy.errors import LaspyException  # noqa: PLC0415

    try:
        return laspy.read(source)
    except LaspyException as exc:
        if "backend" in str(exc).lower() or "lazrs" in str(exc).lower():
            raise FileFormatError(
                f"{source}: reading LAZ needs the lazrs backend: pip install 'seminspect[laz]'"
            ) from None
        raise FileFormatError(f"{source}: not a readable LAS file ({_first_line(exc)})") from None
    except (OSError, ValueError, EOFError) as exc:
        raise FileFormatError(f"{source}: not a readable LAS file ({_first_line(exc)})") from None


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


def header_units(header) -> tuple[str | None, str | None, str]:
    """The linear and vertical units a LAS header declares, and where they were found.

    GeoTIFF keys win over WKT (LAS 1.0-1.3 files carry keys; 1.4 files WKT); a unit neither
    declares is ``None``.
    """
    keys = _geo_keys(header)
    if PROJ_LINEAR_UNITS_KEY in keys:
        unit = GEOTIFF_UNITS.get(keys[PROJ_LINEAR_UNITS_KEY])
        if unit is not None:
            vertical = GEOTIFF_UNITS.get(keys.get(VERTICAL_UNITS_KEY, -1), unit)
            return unit, vertical, f"GeoTIFF key {PROJ_LINEAR_UNITS_KEY}"
    for vlr in header.vlrs:
        wkt = getattr(vlr, "string", None)
        if isinstance(wkt, str):
            # a compound CRS names its vertical CRS (and its unit) after the horizontal one
            unit = wkt_linear_unit(re.split(r"VERT_CS|VERTCRS|VERTICALCRS", wkt)[0])
            if unit is not None:
                return unit, wkt_linear_unit(wkt) or unit, "WKT"
    return None, None, ""


def _geo_keys(header) -> dict[int, int]:
    for vlr in header.vlrs:
        entries = getattr(vlr, "geo_keys", None)
        if entries is not None:
            # a value held in the key itself (location 0) is the short in value_offset
            return {k.id: k.value_offset for k in entries if k.tiff_tag_location == 0}
    return {}


def wkt_linear_unit(wkt: str) -> str | None:
    """``"m"``, ``"ft"`` or ``"us-ft"`` from the last length unit of an OGC WKT string.

    The conversion factor decides (0.3048 is the international foot, 0.3048006 the US survey
    foot), so a unit spelt ``"Foot_US"`` or ``"US survey foot"`` is read alike.
    """
    lengths = [
        float(factor)
        for name, factor in _WKT_UNIT.findall(wkt)
        if not any(word in name.lower() for word in _ANGULAR)
    ]
    if not lengths:
        return None
    factor = lengths[-1]
    for unit, metres in (("m", 1.0), ("ft", 0.3048), ("us-ft", 1200 / 3937)):
        if abs(factor - metres) < 1e-7:
            return unit
    return None


def classification_labels(data: LasPointData, source: Path) -> tuple[NDArray[np.int64], dict]:
    """The file's ASPRS classes as labels and label names (``--labels-from classification``)."""
    if data.classification is None:
        raise FileFormatError(f"{source}: the file has no classification to take labels from")
    codes = data.classification.astype(np.int64)
    names = {int(c): ASPRS_CLASSES.get(int(c), f"class {int(c)}") for c in np.unique(codes)}
    return codes, names
