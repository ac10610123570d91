"""Shared fixtures, among them a small mission run once per session (campus, three cars)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from seminspect.missions.config import make_config
from seminspect.missions.run import MissionResult, run_mission

REPO = Path(__file__).resolve().parents[1]


def _shared_data_dir() -> Path | None:
    candidates = [os.environ.get("SEMINSPECT_SHARED_DATA"), REPO.parent / "shared" / "data"]
    for candidate in candidates:
        if candidate and Path(candidate).is_dir():
            return Path(candidate)
    return None


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The external test data of ``../shared/data``; tests using it skip when it is absent."""
    found = _shared_data_dir()
    if found is None:
        pytest.skip("external test data (../shared/data or $SEMINSPECT_SHARED_DATA) not present")
    return found


class HashingTextEncoder:
    """A tiny deterministic bag-of-words text encoder for tests of the encoder seam.

    Each word maps to a fixed random unit vector (seeded by its bytes); a text embeds as the
    normalised sum of its words, ignoring filler words, so "image of a car" is close to the
    caption "car, automobile, vehicle" and far from "sidewalk".
    """

    name = "hashing-test"
    dim = 256
    _FILLER = frozenset({"a", "an", "the", "of", "image", "photo"})

    def encode_text(self, texts):
        import re

        import numpy as np

        rows = []
        for text in texts:
            total = np.zeros(self.dim)
            for word in re.findall(r"[a-z]+", text.lower()):
                if word not in self._FILLER:
                    seed = int.from_bytes(word.encode()[:8].ljust(8, b"\0"), "little")
                    vector = np.random.default_rng([seed, len(word)]).normal(size=self.dim)
                    total += vector / np.linalg.norm(vector)
            rows.append(total / (np.linalg.norm(total) or 1.0))
        return np.asarray(rows, dtype=np.float32).reshape(len(rows), self.dim)


@pytest.fixture(scope="session")
def fake_encoder():
    """A caption encoder over :class:`HashingTextEncoder`, registered as ``hashing-test``."""
    from seminspect.perception.encoders import Calibration, CaptionEncoder, register_encoder

    calibration = Calibration(terrain=0.45, objects=0.45, null_task=0.3)
    register_encoder("hashing-test", lambda: CaptionEncoder(HashingTextEncoder()), calibration)
    return CaptionEncoder(HashingTextEncoder())


@pytest.fixture(scope="session")
def labelled_scene():
    """A small labelled outdoor scene: road, sidewalk, grass, three cars and two trees."""
    import numpy as np

    xs, ys = np.meshgrid(np.arange(0, 60, 0.3), np.arange(-10, 20, 0.3), indexing="ij")
    ground = np.column_stack([xs.ravel(), ys.ravel(), np.zeros(xs.size)])
    labels = np.where(ground[:, 1] < 0, 2, np.where(ground[:, 1] < 3, 0, 1))
    rng = np.random.default_rng(7)
    parts, part_labels = [ground], [labels]
    for x0 in (8.0, 25.0, 45.0):  # cars on the road
        car = rng.uniform([x0, -6.0, 0.2], [x0 + 4.2, -4.2, 1.6], (700, 3))
        parts.append(car)
        part_labels.append(np.full(700, 3))
    for x0, y0 in ((15.0, 10.0), (40.0, 12.0)):  # tree trunks and crowns on the grass
        angle = rng.uniform(0, 2 * np.pi, 500)
        height = rng.uniform(0, 4, 500)
        radius = np.where(height > 2, 0.8, 0.3)
        tree = np.column_stack([x0 + radius * np.cos(angle), y0 + radius * np.sin(angle), height])
        parts.append(tree)
        part_labels.append(np.full(500, 4))
    names = {0: "sidewalk", 1: "grass", 2: "road", 3: "car", 4: "tree"}
    return np.vstack(parts), np.concatenate(part_labels), names


#: 000 Table 5 style queries, and one naming a part a ground robot cannot see (a hood's top).
QUERIES = [
    "Visit car-0",
    "Observe front-bumper-1 in Level-0 of car-1",
    "Visit hood-1 in Level-0 of car-2",
]


@pytest.fixture(scope="session")
def mission_queries() -> list[str]:
    return list(QUERIES)


@pytest.fixture(scope="session")
def small_mission(tmp_path_factory: pytest.TempPathFactory) -> MissionResult:
    out = tmp_path_factory.mktemp("mission") / "campus-small"
    config = make_config({"world": "campus", "scenario": "small", "seed": 0})
    return run_mission(config, out, queries=QUERIES)


@pytest.fixture(scope="session")
def small_mission_dir(small_mission: MissionResult) -> Path:
    return small_mission.run_dir
