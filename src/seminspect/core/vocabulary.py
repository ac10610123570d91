"""Semantic vocabularies shared by the worlds, the graphs and the missions."""

from __future__ import annotations

#: The inspection features of a vehicle: every named part a generated vehicle carries, besides
#: ``body`` and ``roof`` (000 Table 5 queries name these: front-bumper, back-left-door, ...).
VEHICLE_PARTS: tuple[str, ...] = (
    "hood",
    "trunk",
    "front-bumper",
    "back-bumper",
    "front-glass",
    "back-glass",
    "front-left-door",
    "front-right-door",
    "back-left-door",
    "back-right-door",
    "front-left-wheel",
    "front-right-wheel",
    "back-left-wheel",
    "back-right-wheel",
    "front-left-light",
    "front-right-light",
    "back-left-light",
    "back-right-light",
)

#: The inspection features of a collapsed building (000 Sec VI-B, Table 2 scenario).
BUILDING_FEATURES: tuple[str, ...] = ("window", "person", "rubble")

#: Parts that are the object itself, not features on it: a vehicle's ``body`` and ``roof``, a
#: building's ``wall`` and ``roof``. The built-in worlds name these and the features above, and
#: a world's feature labels are its targets' parts without these (missions.xflie.features).
STRUCTURE_PARTS: tuple[str, ...] = ("body", "roof", "wall")

#: The built-in features in their published order, which orders a world's feature labels.
KNOWN_FEATURES: tuple[str, ...] = VEHICLE_PARTS + BUILDING_FEATURES
