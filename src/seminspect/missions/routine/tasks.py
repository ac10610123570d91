"""Inspection tasks for routine missions: regions from a YAML/JSON file or a site's defaults.

A task file lists named flat polygons on the historical map::

    regions:
      - name: face
        vertices: [[20.0, 1.3, 0.8], [20.0, 3.7, 0.8], [20.0, 3.7, 2.4], [20.0, 1.3, 2.4]]

Each region is validated by :class:`~seminspect.planning.global_views.InspectionRegion`
(at least three finite vertices, planar within 5 cm, wall-like) and must be a simple polygon
(its outline does not cross itself); a broken file is a ``FileFormatError`` naming the file and
the region. Given the site, a region outside the site's bounds is refused too: it would plan
no views and end the mission with "0 of 1 tasks".
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError
from shapely import Polygon
from shapely.validation import explain_validity

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import read_json
from seminspect.core.validation import describe_validation_error
from seminspect.planning.global_views import InspectionRegion
from seminspect.worlds.routine_sites import SitePair


class _Region(BaseModel):
    model_config = ConfigDict(extra="forbid")

    name: str = Field(min_length=1)
    vertices: list[tuple[float, float, float]]


class _TaskFile(BaseModel):
    model_config = ConfigDict(extra="forbid")

    regions: list[_Region] = Field(min_length=1)


#: How far a region may lie outside the site's bounds and still count as on the site [m]:
#: a wall region lies on the boundary itself.
SITE_TOLERANCE_M = 0.5


def load_tasks(
    path: str | os.PathLike[str], site: SitePair | None = None
) -> list[InspectionRegion]:
    """The regions of a ``.yaml``/``.yml``/``.json`` task file; with ``site``, each must
    overlap the site's historical bounds (:func:`check_regions`)."""
    regions = _read_regions(Path(path))
    for region in regions:
        _check_simple(region, path)
    if site is not None:
        check_regions(regions, site, path)
    return regions


def check_regions(
    regions: list[InspectionRegion], site: SitePair, source: str | os.PathLike[str]
) -> None:
    """Refuse a region that does not overlap the site's bounds, naming it and ``source``."""
    bounds = np.asarray(site.historical.bounds, dtype=np.float64)
    for region in regions:
        low, high = region.vertices.min(axis=0), region.vertices.max(axis=0)
        apart = np.maximum(low - bounds[1], bounds[0] - high)  # > 0 along an axis: no overlap
        if np.any(apart > SITE_TOLERANCE_M):
            spans, site_spans = describe_box(low, high), describe_box(*bounds)
            raise FileFormatError(
                f"{source}: region {region.name!r} spans {spans}, outside the site "
                f"({site_spans}); give its vertices in the site's coordinates"
            )


def describe_box(low: np.ndarray, high: np.ndarray) -> str:
    """``x 0.0..21.0 y 0.0..5.0 z 0.0..4.5``: an axis-aligned box for a message."""
    return " ".join(f"{a} {lo:.1f}..{hi:.1f}" for a, lo, hi in zip("xyz", low, high, strict=True))


def _check_simple(region: InspectionRegion, source: str | os.PathLike[str]) -> None:
    """A region whose outline crosses itself has no inside to inspect."""
    outline = Polygon(region.plane_coordinates(region.vertices))
    if not outline.is_valid:
        why = explain_validity(outline)
        raise FileFormatError(
            f"{source}: region {region.name!r} is not a simple polygon ({why}); "
            "list its vertices in order around its outline"
        )


def _read_regions(source: Path) -> list[InspectionRegion]:
    document = _read_document(source)
    try:
        parsed = _TaskFile.model_validate(document)
    except ValidationError as exc:
        raise FileFormatError(f"{source}: {describe_validation_error(exc, 'task file')}") from None
    names = [region.name for region in parsed.regions]
    if len(set(names)) != len(names):
        raise FileFormatError(f"{source}: region names must be unique, got {names}")
    try:
        return [
            InspectionRegion(r.name, np.asarray(r.vertices, dtype=np.float64))
            for r in parsed.regions
        ]
    except InvalidInputError as exc:
        raise FileFormatError(f"{source}: {exc}") from None


def _read_document(source: Path) -> object:
    if source.suffix.lower() not in (".yaml", ".yml", ".json"):
        raise FileFormatError(f"{source}: task files are .yaml, .yml or .json")
    if source.suffix.lower() == ".json":
        return read_json(source)
    try:
        return yaml.safe_load(source.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise FileFormatError(f"{source}: no such file") from None
    except (yaml.YAMLError, UnicodeDecodeError) as exc:
        raise FileFormatError(f"{source}: not valid YAML ({type(exc).__name__})") from None


def default_tasks(site: SitePair) -> list[InspectionRegion]:
    """The site's default regions; a user site has none and needs a task file."""
    if not site.tasks:
        raise InvalidInputError(
            f"site {site.name!r} has no default tasks; pass a task file (--tasks FILE: regions "
            "on the site's walls, in its coordinates)"
        )
    return [InspectionRegion(name, vertices) for name, vertices in site.tasks]
