"""The outcomes of one evaluation batch, and a store of finished batches on disk.

A batch of the evaluation protocol (:mod:`.evaluation`) is a deterministic unit: its rooms
follow from the seed, the obstacle count and the batch index, and every controller clears its
state at the batch's reset. So a finished batch can be kept and reused: an evaluation stopped
part-way (500 episodes per cell take hours on a laptop) resumes where it stopped, and several
processes given different obstacle counts fill one store that a last run then assembles.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError
from seminspect.core.io import read_versioned_json, write_versioned_json
from seminspect.missions.learning.env_config import EnvConfig

BATCH_FORMAT = "seminspect.rl-evaluation-batch"
BATCH_VERSION = 2  # 2: what each crash struck


@dataclass
class BatchTally:
    """Per-episode outcomes (of one batch, or of an obstacle count's batches together) and
    the seconds spent computing them."""

    coverage: list[float] = field(default_factory=list)
    strict: list[float] = field(default_factory=list)
    scores: list[float] = field(default_factory=list)
    feasible: list[int] = field(default_factory=list)
    crashed: list[bool] = field(default_factory=list)
    timed_out: list[bool] = field(default_factory=list)
    length: list[int] = field(default_factory=list)
    struck: list[str] = field(default_factory=list)  # what each crash struck; "": none
    rooms: list[str] = field(default_factory=list)
    curves: list[NDArray[np.float64]] = field(default_factory=list)
    seconds: float = 0.0

    def extend(self, other: BatchTally) -> None:
        """Append another batch's episodes (in order) and add its seconds."""
        for name in (f.name for f in fields(self) if f.name != "seconds"):
            getattr(self, name).extend(getattr(other, name))
        self.seconds += other.seconds

    def to_payload(self) -> dict[str, Any]:
        return asdict(self) | {"curves": [np.asarray(c).tolist() for c in self.curves]}

    @classmethod
    def from_payload(cls, payload: Mapping[str, Any]) -> BatchTally:
        values = dict(payload)
        values["curves"] = [np.asarray(c, dtype=np.float64) for c in values["curves"]]
        return cls(**values)


class BatchStore:
    """Finished batches as JSON files in ``directory``, named by a digest of everything that
    decides their outcome: ``identity`` (what is flown, e.g. the checkpoint's SHA-256 and the
    evaluation's name: the caller's to make unique), the env config, the seed, the batch index
    and its size. A batch flown by anything else never matches; a damaged file is refused."""

    def __init__(self, directory: str | Path, identity: Mapping[str, Any]) -> None:
        self.directory = Path(directory)
        self.identity = dict(identity)

    def path(self, config: EnvConfig, seed: int, batch: int, size: int) -> Path:
        decided = {  # the version too: a batch of another layout is flown again, not misread
            "version": BATCH_VERSION,
            "identity": self.identity,
            "config": config.model_dump(mode="json"),
            "seed": seed,
            "batch": batch,
            "size": size,
        }
        digest = hashlib.sha256(json.dumps(decided, sort_keys=True).encode()).hexdigest()[:16]
        return self.directory / f"k{config.obstacles}-b{batch}-{digest}.json"

    def load(self, config: EnvConfig, seed: int, batch: int, size: int) -> BatchTally | None:
        """The stored batch, or None when it has not been finished."""
        path = self.path(config, seed, batch, size)
        if not path.exists():
            return None
        document = read_versioned_json(path, BATCH_FORMAT, [BATCH_VERSION])
        try:
            tally = BatchTally.from_payload(document["tally"])
        except (KeyError, TypeError, ValueError) as exc:
            raise FileFormatError(f"{path}: not a stored evaluation batch ({exc})") from None
        if len(tally.coverage) != size:
            raise FileFormatError(f"{path}: holds {len(tally.coverage)} episodes, not {size}")
        return tally

    def save(self, config: EnvConfig, seed: int, batch: int, tally: BatchTally) -> Path:
        """Keep a finished batch (atomically: a stop mid-write leaves no half file)."""
        self.directory.mkdir(parents=True, exist_ok=True)
        path = self.path(config, seed, batch, len(tally.coverage))
        payload = {"tally": tally.to_payload()}
        return write_versioned_json(path, BATCH_FORMAT, BATCH_VERSION, payload)
