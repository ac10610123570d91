"""Shared fixtures, among them a small mission run once per session (campus, three cars)."""

from __future__ import annotations

import os
import shutil
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np
import pytest
from filelock import FileLock
from numpy.typing import NDArray

from seminspect.core.io import read_versioned_json
from seminspect.graphs.lsg.graph import LayeredSemanticGraph
from seminspect.graphs.lsg.io import load_graph
from seminspect.mapping.voxel import VoxelMap, load_map
from seminspect.missions.xflie.config import ResolvedMissionConfig, make_config, resolve
from seminspect.missions.xflie.metrics import MissionMetrics, QueryAnswer
from seminspect.missions.xflie.run import run_mission
from seminspect.runs.directory import read_run_config
from seminspect.runs.trajectory import load_trajectory
from seminspect.worlds import World, generate_world

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


@dataclass(frozen=True)
class SavedRun:
    """A finished run as its directory holds it: what the tests of the shared mission read."""

    run_dir: Path
    state: str
    reason: str
    config: ResolvedMissionConfig
    metrics: MissionMetrics
    graph: LayeredSemanticGraph
    occupancy: VoxelMap
    #: The robot's last odometry position.
    final_position: NDArray[np.float64]

    @property
    def answers(self) -> list[QueryAnswer]:
        return self.metrics.queries

    @cached_property
    def world(self) -> World:
        """The run's world, generated again from its seed."""
        return generate_world(self.config.world, self.config.scenario, seed=self.config.seed)

    @classmethod
    def read(cls, run_dir: Path) -> SavedRun:
        status = read_versioned_json(run_dir / "status.json", "seminspect.run-status", [1])
        metrics = read_versioned_json(run_dir / "metrics.json", "seminspect.run-metrics", [1])
        return cls(
            run_dir,
            status["state"],
            status["reason"],
            resolve(make_config(read_run_config(run_dir))),
            MissionMetrics.from_json(metrics),
            load_graph(run_dir / "graph.json"),
            load_map(run_dir / "map.npz"),
            load_trajectory(run_dir)[-1, 5:8],
        )


def _completed(run_dir: Path) -> bool:
    status = run_dir / "status.json"
    if not status.exists():
        return False
    return read_versioned_json(status, "seminspect.run-status", [1])["state"] == "completed"


@pytest.fixture(scope="session")
def small_mission_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The shared small mission's run directory, run once per test session.

    Under xdist every worker has its own temporary directory below one the session shares;
    the first worker to take the lock runs the mission there, the others wait and read it.
    """
    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent
    out = root / "shared-mission" / "campus-small"
    with FileLock(str(root / "shared-mission.lock")):
        if not _completed(out):
            shutil.rmtree(out, ignore_errors=True)
            config = make_config({"world": "campus", "scenario": "small", "seed": 0})
            run_mission(config, out, queries=QUERIES)
    return out


@pytest.fixture(scope="session")
def small_mission(small_mission_dir: Path) -> SavedRun:
    return SavedRun.read(small_mission_dir)


def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter) -> None:
    """Say which checks the golden mission ran (``tests/missions/xflie/test_golden.py``): exact,
    on a machine with a golden file, and the behavioural envelope, everywhere; or why one
    skipped."""
    lines = []
    for report in terminalreporter.stats.get("passed", []):
        lines += [str(value) for name, value in report.user_properties if name == "golden check"]
    for report in terminalreporter.stats.get("skipped", []):
        if "test_golden.py" in report.nodeid and isinstance(report.longrepr, tuple):
            lines.append(str(report.longrepr[2]).removeprefix("Skipped: "))
    if lines:
        terminalreporter.write_sep("-", "golden mission")
        for line in lines:
            terminalreporter.write_line(line)
