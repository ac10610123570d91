"""The built-in worlds by name: :func:`generate_world` and :func:`available_worlds`."""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from seminspect.core.errors import InvalidInputError
from seminspect.core.names import unknown_name
from seminspect.worlds import campus, city, collapsed, outdoor, rooms
from seminspect.worlds.sdf import SDF_SUFFIXES
from seminspect.worlds.underground import generate_mine_drift, generate_subterranean
from seminspect.worlds.user import (
    LABELS_SUFFIXES,
    MESH_SUFFIXES,
    OCTOMAP_SUFFIXES,
    load_world_path,
)
from seminspect.worlds.world import World


@dataclass(frozen=True)
class WorldSpec:
    """A generator: its name, a one-line description, scenarios and extra options."""

    name: str
    description: str
    scenarios: tuple[str, ...]
    default_scenario: str
    build: Callable[..., World] = field(repr=False)
    options: dict[str, Any] = field(default_factory=dict)


def _city(scenario: str, seed: int, **options: Any) -> World:
    return city.generate_city(scenario, seed, **options)


def _subterranean(scenario: str, seed: int) -> World:
    del scenario  # one tunnel section only
    return generate_subterranean(seed)


WORLDS: dict[str, WorldSpec] = {
    spec.name: spec
    for spec in (
        WorldSpec(
            "city",
            "150 x 100 x 5 m streets and buildings with 5/10/20 cars and trucks (000 Sec VI-B)",
            tuple(city.SCENARIOS),
            "large",
            _city,
            {"truck_share": 0.3},
        ),
        WorldSpec(
            "collapsed-buildings",
            "collapsed multi-storey buildings with windows, people and rubble (000 Table 2)",
            tuple(collapsed.SCENARIOS),
            "fire-station",
            collapsed.generate_collapsed,
        ),
        WorldSpec(
            "campus",
            "40 x 24 x 2 m campus with 3/5/7 parked cars (000 Sec VI-C)",
            tuple(campus.SCENARIOS),
            "medium",
            campus.generate_campus,
        ),
        WorldSpec(
            "subterranean",
            "10 x 6 x 4 m rough tunnel section with one car (000 Sec VI-C)",
            ("tunnel",),
            "tunnel",
            _subterranean,
        ),
        WorldSpec(
            "mine-drift",
            "mine drift ending in a rock face; 'current' has a receded face and a boulder (002)",
            ("historical", "current"),
            "historical",
            generate_mine_drift,
            {"length": 40.0, "recession": 1.0, "obstacle": True},
        ),
        WorldSpec(
            "outdoor",
            "100 x 60 m sidewalks, grass and asphalt with 8 cars and 12 trees, a drive path (001)",
            tuple(outdoor.SCENARIOS),
            "block",
            outdoor.generate_outdoor,
        ),
        WorldSpec(
            "room",
            "room with 0-19 primitive obstacles and one target (004 Sec III-E)",
            tuple(rooms.SCENARIOS),
            "9",
            rooms.generate_room,
        ),
    )
}


def available_worlds() -> list[WorldSpec]:
    """Every built-in world with its description and scenarios."""
    return list(WORLDS.values())


def generate_world(name: str, scenario: str | None = None, seed: int = 0, **options: Any) -> World:
    """Generate a built-in world; the same arguments always give the same world.

    Args:
        name: one of :func:`available_worlds`.
        scenario: one of the world's scenarios (its default when omitted).
        seed: non-negative seed of every random choice.
        options: world-specific settings (see ``WorldSpec.options``).
    """
    try:
        spec = WORLDS[name]
    except KeyError:
        raise unknown_name("world", name, WORLDS) from None
    chosen = spec.default_scenario if scenario is None else scenario
    if chosen not in spec.scenarios:
        raise unknown_name(f"{name} scenario", chosen, spec.scenarios)
    unknown = set(options) - set(spec.options)
    if unknown:
        valid = ", ".join(sorted(spec.options)) or "none"
        raise InvalidInputError(f"{name} has no option {sorted(unknown)}; options: {valid}")
    if not isinstance(seed, int) or seed < 0:
        raise InvalidInputError(f"seed must be a non-negative integer, got {seed!r}")
    world = spec.build(chosen, seed, **options)
    world.metadata.update(
        {"generator": name, "scenario": chosen, "options": {**spec.options, **options}}
    )
    return world


def open_world(name_or_path: str, scenario: str | None = None, seed: int = 0) -> World:
    """A built-in world by name, or a user world by path: a site file, an SDF world, a mesh
    with its labels (see ``worlds.user.load_world_path``); a user world is fixed, so it takes
    no scenario and ignores ``seed``."""
    if name_or_path in WORLDS:
        return generate_world(name_or_path, scenario, seed)
    if not is_world_path(name_or_path):
        raise unknown_name("world", name_or_path, WORLDS, "(nor a world file path)")
    if scenario is not None:
        raise InvalidInputError(f"{name_or_path} is a user world, which has no scenarios")
    return load_world_path(name_or_path)


def is_world_path(text: str) -> bool:
    """Whether ``text`` names a file or folder rather than a built-in world."""
    suffix = Path(text).suffix.lower()
    suffixes = MESH_SUFFIXES + LABELS_SUFFIXES + SDF_SUFFIXES + OCTOMAP_SUFFIXES
    return os.sep in text or suffix in suffixes or Path(text).exists()
