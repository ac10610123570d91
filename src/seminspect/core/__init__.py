"""Foundations shared by every layer: errors, atomic I/O, seeded randomness, paper parameters."""

from seminspect.core.errors import (
    FileFormatError,
    InvalidInputError,
    PlanningError,
    SeminspectError,
    UnknownNameError,
)
from seminspect.core.io import (
    atomic_write_text,
    read_versioned_json,
    save_npz_atomic,
    write_versioned_json,
)
from seminspect.core.params import PRESETS, InspectionParams, make_params
from seminspect.core.rng import make_rng
from seminspect.core.validation import build

__all__ = [
    "PRESETS",
    "FileFormatError",
    "InspectionParams",
    "InvalidInputError",
    "PlanningError",
    "SeminspectError",
    "UnknownNameError",
    "atomic_write_text",
    "build",
    "make_params",
    "make_rng",
    "read_versioned_json",
    "save_npz_atomic",
    "write_versioned_json",
]
