"""Small vehicle meshes written in the tests: OBJ files whose groups name their parts."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
import trimesh


def obj_text(groups: dict[str, trimesh.Trimesh]) -> str:
    """An OBJ file with one ``g`` group per named mesh."""
    lines, offset = [], 0
    for mesh in groups.values():
        lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in mesh.vertices]
    for name, mesh in groups.items():
        lines.append(f"g {name}")
        lines += [f"f {a + offset + 1} {b + offset + 1} {c + offset + 1}" for a, b, c in mesh.faces]
        offset += len(mesh.vertices)
    return "\n".join(lines) + "\n"


def toy_car(length: float = 4.0, width: float = 2.0) -> dict[str, trimesh.Trimesh]:
    """A car whose front is its -y side (as Gazebo's Prius): a body and four wheels, the
    front ones at -y; its lowest point is z = 0."""
    body = trimesh.creation.box(extents=(width, length, 1.2))
    body.apply_translation((0.0, 0.0, 0.9))
    parts = {"Body": body}
    for name, x, y in (
        ("Wheel_FL", width / 2 - 0.15, -length / 2 + 0.7),
        ("Wheel_FR", -width / 2 + 0.15, -length / 2 + 0.7),
        ("Wheels_Rear", 0.0, length / 2 - 0.7),
    ):
        extents = (0.3 if name != "Wheels_Rear" else width, 0.6, 0.6)
        wheel = trimesh.creation.box(extents=extents)
        wheel.apply_translation((x, y, 0.3))
        parts[name] = wheel
    return parts


@pytest.fixture
def car_obj(tmp_path: Path) -> Callable[..., Path]:
    """Write a toy car OBJ (see :func:`toy_car`) under ``tmp_path`` and return its path."""

    def write(name: str = "car.obj", scale: float = 1.0, **sizes: float) -> Path:
        path = tmp_path / name
        parts = toy_car(**sizes)
        for mesh in parts.values():
            mesh.apply_scale(1.0 / scale)
        path.write_text(obj_text(parts))
        return path

    return write
