"""Inspection tasks for routine missions: regions from a YAML/JSON file or a site's defaults.

A task file lists named flat polygons on the historical map::

    regions:
      - name: face
        vertices: [[20.0, 1.3, 0.8], [20.0, 3.7, 0.8], [20.0, 3.7, 2.4], [20.0, 1.3, 2.4]]

Each region is validated by :class:`~seminspect.planning.global_views.InspectionRegion`
(at least three finite vertices, planar within 5 cm, wall-like); a broken file is a
``FileFormatError`` naming the file and the region.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError

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


def load_tasks(path: str | os.PathLike[str]) -> list[InspectionRegion]:
    """The regions of a ``.yaml``/``.yml``/``.json`` task file."""
    source = Path(path)
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
        raise InvalidInputError(f"site {site.name!r} has no default tasks; pass a task file")
    return [InspectionRegion(name, vertices) for name, vertices in site.tasks]
