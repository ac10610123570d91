"""A labelled dataset of colour frames, rendered from the simulator, to train a segmentation
network that would replace the simulator's labels as the detector (000 Sec III).

Frames come from a list of worlds, each world under training seeds only (10000 up; the
evaluation missions use 0-59), each frame under its own appearance (:mod:`seminspect.sensors.
appearance`) from [0, 1,000,000); a held-out dataset takes worlds from 20000 up and appearances
from [1,000,000, 2,000,000), which training never sees. Labels are the dataset's own, shared by
every frame whatever its world: classes ``background, car, truck, building`` (ground, sky and
any other object are background) and the targets' parts.

A dataset is a directory: ``dataset.json`` (format ``seminspect.detector-dataset``, version 1:
the label space, the plan of every shard, the arguments that made it) and shards
``frames-00000.npz``, ... written whole or not at all. Each shard's draws follow from (seed,
shard index) alone, so an interrupted run, rerun with the same arguments, renders the missing
shards into the same bytes an uninterrupted run writes.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

import seminspect
from seminspect.core.errors import InvalidInputError
from seminspect.core.io import atomic_write_bytes, read_versioned_json, write_versioned_json
from seminspect.core.rng import make_rng
from seminspect.perception.dataset_format import (
    FORMAT,
    MANIFEST,
    SHARD_ARRAYS,
    VERSION,
    Dataset,
    DatasetFrame,
    DatasetStatistics,
    dataset_statistics,
    load_dataset,
    npz_bytes,
    shard_name,
)
from seminspect.perception.dataset_views import (
    RANDOM_VIEW_SHARE,
    TARGET_CLASSES,
    Viewpoint,
    draw_viewpoint,
    target_instances,
)
from seminspect.sensors import CameraModel, Frame, render
from seminspect.sensors.appearance import Appearance, add_colour_noise
from seminspect.worlds import World, open_world

#: The dataset's classes: every world's labels are mapped into these.
CLASSES: tuple[str, ...] = ("background", *TARGET_CLASSES)
DEFAULT_WORLDS: tuple[tuple[str, str | None], ...] = (
    ("city", "small"),
    ("city", "medium"),
    ("campus", "small"),
)
#: First world seed of a training and of a held-out dataset; each spans this many seeds, one
#: per shard, above the evaluation seeds (0-59).
TRAINING_WORLD_SEEDS = 10_000
HELD_OUT_WORLD_SEEDS = 20_000
SEED_BLOCK = 10_000
#: Appearance seeds ``[low, high)`` of training and held-out frames: never the same.
TRAINING_APPEARANCES = (0, 1_000_000)
HELD_OUT_APPEARANCES = (1_000_000, 2_000_000)
#: The mission camera's field of view (000 Table 1) and the colour sensor's noise (levels).
HFOV_DEG = 69.4
NOISE_SIGMA = 4.0
#: A frame is drawn again when this share of its pixels is nearer than this (m): inside or
#: against an object; or, looking at a target, when under this share of pixels shows it.
NEAR_DEPTH, NEAR_SHARE = 0.3, 0.5
MIN_TARGET_SHARE = 0.005
#: Draws allowed for one frame before the world is declared unable to show its targets.
MAX_ATTEMPTS = 100

Progress = Callable[[int, int], None]

__all__ = [
    "CLASSES",
    "FORMAT",
    "VERSION",
    "Dataset",
    "DatasetFrame",
    "DatasetSpec",
    "DatasetStatistics",
    "build_dataset",
    "dataset_statistics",
    "load_dataset",
    "parse_worlds",
]


@dataclass(frozen=True)
class DatasetSpec:
    """What a dataset is made of: the arguments that, with the code, fix every byte of it."""

    worlds: tuple[tuple[str, str | None], ...] = DEFAULT_WORLDS
    frames: int = 2000
    width: int = 320
    height: int = 240
    held_out: bool = False
    seed: int = 0
    shard_size: int = 64

    def __post_init__(self) -> None:
        if not self.worlds:
            raise InvalidInputError("a dataset needs at least one world")
        if self.frames < 1:
            raise InvalidInputError(f"frames must be at least 1, got {self.frames}")
        if not 1 <= self.shard_size <= 4096:
            raise InvalidInputError(f"shard size must be 1-4096 frames, got {self.shard_size}")
        if self.shards > SEED_BLOCK:
            raise InvalidInputError(
                f"{self.shards} shards would leave the {SEED_BLOCK} world seeds of a split; "
                "use larger shards"
            )
        if self.seed < 0:
            raise InvalidInputError(f"seed must be non-negative, got {self.seed}")
        CameraModel(self.width, self.height, HFOV_DEG)  # checks the size

    @property
    def split(self) -> str:
        return "held-out" if self.held_out else "training"

    @property
    def shards(self) -> int:
        return -(-self.frames // self.shard_size)

    @property
    def camera(self) -> CameraModel:
        return CameraModel(self.width, self.height, HFOV_DEG)

    @property
    def world_names(self) -> list[str]:
        """``name:scenario`` of each world (``name`` alone for its default scenario)."""
        return [name if scene is None else f"{name}:{scene}" for name, scene in self.worlds]

    def world_seed(self, shard: int) -> int:
        """The seed every world of ``shard`` is generated from."""
        return (HELD_OUT_WORLD_SEEDS if self.held_out else TRAINING_WORLD_SEEDS) + shard

    def shard_frames(self, shard: int) -> int:
        if not 0 <= shard < self.shards:
            raise InvalidInputError(f"shard {shard} is not one of this dataset's {self.shards}")
        return min(self.shard_size, self.frames - shard * self.shard_size)

    def frame_worlds(self, shard: int) -> list[int]:
        """Index into :attr:`worlds` of each frame of ``shard``: the worlds in turn."""
        start = shard * self.shard_size
        return [(start + j) % len(self.worlds) for j in range(self.shard_frames(shard))]

    def appearance_seeds(self, shard: int) -> list[int]:
        """The appearance seed of each frame of ``shard``, from its own stream."""
        low, high = HELD_OUT_APPEARANCES if self.held_out else TRAINING_APPEARANCES
        rng = make_rng(self.seed, "perception", "dataset", self.split, "appearance", str(shard))
        return [int(s) for s in rng.integers(low, high, self.shard_frames(shard))]

    def arguments(self) -> dict[str, Any]:
        """The arguments as recorded in ``dataset.json``; a rerun must give the same."""
        return {
            "worlds": self.world_names,
            "frames": self.frames,
            "size": [self.width, self.height],
            "held_out": self.held_out,
            "seed": self.seed,
            "shard_size": self.shard_size,
        }


def parse_worlds(text: str) -> tuple[tuple[str, str | None], ...]:
    """``city:small,campus`` as ``(("city", "small"), ("campus", None))``."""
    pairs: list[tuple[str, str | None]] = []
    for item in (part.strip() for part in text.split(",")):
        name, _, scenario = item.partition(":")
        if not name:
            raise InvalidInputError(f"worlds are name[:scenario] separated by commas, got {text!r}")
        pairs.append((name, scenario or None))
    return tuple(pairs)


# ----------------------------------------------------------------------------- building
def build_dataset(
    out: str | Path,
    spec: DatasetSpec,
    *,
    on_progress: Progress | None = None,
    command: str | None = None,
) -> Dataset:
    """Render the dataset ``spec`` into ``out``, or finish one an interrupted run began.

    Shards already there are kept (they are whole: each is written under a temporary name,
    then renamed); a directory made with other arguments is refused.
    """
    directory = Path(out)
    first = _open_worlds(spec, 0)
    manifest = _manifest(spec, _part_vocabulary(first), command)
    _claim(directory, manifest)
    parts = manifest["parts"]
    done = sum(spec.shard_frames(k) for k in range(spec.shards) if _has_shard(directory, k))
    if on_progress is not None:
        on_progress(done, spec.frames)
    for shard in range(spec.shards):
        if _has_shard(directory, shard):
            continue
        worlds = first if shard == 0 else _open_worlds(spec, shard)
        step = _counter(on_progress, done, spec)
        arrays = render_shard(spec, shard, worlds, parts, on_frame=step)
        atomic_write_bytes(directory / shard_name(shard), npz_bytes(arrays))
        done += spec.shard_frames(shard)
    return load_dataset(directory)


def _counter(on_progress: Progress | None, done: int, spec: DatasetSpec) -> Callable[[], None]:
    count = [done]

    def step() -> None:
        count[0] += 1
        if on_progress is not None:
            on_progress(count[0], spec.frames)

    return step


def _has_shard(directory: Path, shard: int) -> bool:
    return (directory / shard_name(shard)).is_file()


def _open_worlds(spec: DatasetSpec, shard: int) -> list[World]:
    """Every world of ``shard``, each of which must hold a target."""
    worlds = []
    for (name, scenario), label in zip(spec.worlds, spec.world_names, strict=True):
        world = open_world(name, scenario, seed=spec.world_seed(shard))
        if not target_instances(world):
            raise InvalidInputError(f"{label} holds no {', '.join(TARGET_CLASSES)} to look at")
        worlds.append(world)
    return worlds


def _part_vocabulary(worlds: Sequence[World]) -> list[str]:
    """``none`` and the sorted union of the targets' part names (the first shard's worlds:
    a generator gives its targets the same parts under every seed)."""
    names = {
        part
        for world in worlds
        for infos in target_instances(world).values()
        for info in infos
        for part in info.parts
    }
    return ["none", *sorted(names)]


def _manifest(spec: DatasetSpec, parts: list[str], command: str | None) -> dict[str, Any]:
    arguments = spec.arguments()
    return {
        "classes": list(CLASSES),
        "parts": parts,
        "image_size": [spec.width, spec.height],
        "hfov_deg": HFOV_DEG,
        "frames": spec.frames,
        "split": spec.split,
        "noise_sigma": NOISE_SIGMA,
        "worlds": spec.world_names,
        "shards": [_shard_record(spec, k) for k in range(spec.shards)],
        "arguments": arguments,
        "command": command or _command_line(arguments),
        "seminspect": seminspect.__version__,
    }


def _shard_record(spec: DatasetSpec, shard: int) -> dict[str, Any]:
    return {
        "file": shard_name(shard),
        "frames": spec.shard_frames(shard),
        "world_seed": spec.world_seed(shard),
        "frame_worlds": spec.frame_worlds(shard),
        "appearance_seeds": spec.appearance_seeds(shard),
    }


def _command_line(arguments: dict[str, Any]) -> str:
    """The CLI command that makes a dataset of these arguments (output directory aside)."""
    width, height = arguments["size"]
    return (
        f"seminspect perception dataset --frames {arguments['frames']} "
        f"--worlds {','.join(arguments['worlds'])} --size {width}x{height} "
        f"--seed {arguments['seed']} --shard-size {arguments['shard_size']}"
        + (" --held-out" if arguments["held_out"] else "")
    )


def _claim(directory: Path, manifest: dict[str, Any]) -> None:
    """Make ``directory`` this dataset's: new, empty, or one begun with the same arguments."""
    path = directory / MANIFEST
    if path.is_file():
        found = read_versioned_json(path, FORMAT, [VERSION])
        same = all(found.get(key) == manifest[key] for key in ("arguments", "parts"))
        if not same:
            raise InvalidInputError(
                f"{directory} holds a dataset made by '{found.get('command')}'; "
                "rerun that command to finish it, or choose another --out"
            )
        if found.get("seminspect") != manifest["seminspect"]:
            warnings.warn(
                f"{directory} was begun by seminspect {found.get('seminspect')}, continued by "
                f"{manifest['seminspect']}: its shards may differ from one run's",
                stacklevel=2,
            )
        return
    if directory.is_dir() and any(directory.iterdir()):
        raise InvalidInputError(
            f"{directory} is not empty and holds no {MANIFEST}; choose another --out"
        )
    directory.mkdir(parents=True, exist_ok=True)
    write_versioned_json(path, FORMAT, VERSION, manifest, indent=1)


# ----------------------------------------------------------------------------- rendering
@dataclass(frozen=True)
class _Labels:
    """One world's class and part ids mapped into the dataset's."""

    classes: NDArray[np.uint8]
    parts: NDArray[np.uint8]

    @classmethod
    def of(cls, world: World, parts: Sequence[str]) -> _Labels:
        classes = np.zeros(len(world.class_names), np.uint8)
        for index, name in enumerate(world.class_names):
            if name in TARGET_CLASSES:
                classes[index] = CLASSES.index(name)
        carried = {p for infos in target_instances(world).values() for i in infos for p in i.parts}
        if unknown := carried - set(parts):
            raise InvalidInputError(
                f"{world.name} (seed {world.seed}) has target parts outside the dataset's "
                f"vocabulary: {', '.join(sorted(unknown))}"
            )
        part_ids = np.zeros(len(world.part_names), np.uint8)
        for index, name in enumerate(world.part_names):
            if name in parts:
                part_ids[index] = parts.index(name)
        return cls(classes, part_ids)


def render_shard(
    spec: DatasetSpec,
    shard: int,
    worlds: Sequence[World],
    parts: Sequence[str],
    on_frame: Callable[[], None] | None = None,
) -> dict[str, np.ndarray]:
    """Every array of one shard (see :data:`SHARD_ARRAYS`), drawn from (seed, shard) alone."""
    rng = make_rng(spec.seed, "perception", "dataset", spec.split, "views", str(shard))
    labels = [_Labels.of(world, parts) for world in worlds]
    rows: list[dict[str, Any]] = []
    seeds = spec.appearance_seeds(shard)
    for j, (index, appearance_seed) in enumerate(zip(spec.frame_worlds(shard), seeds, strict=True)):
        world = worlds[index]
        appearance = Appearance.draw(world, appearance_seed)
        frame, view = _render_view(world, spec.camera, appearance, rng)
        noise = make_rng(spec.seed, "perception", "dataset", spec.split, "noise", f"{shard}-{j}")
        rows.append(_frame_arrays(frame, view, labels[index], noise))
        rows[-1].update(world=index, world_seed=world.seed, appearance_seed=appearance_seed)
        if on_frame is not None:
            on_frame()
    return {
        name: np.stack([row[name] for row in rows]).astype(dtype)
        for name, dtype in SHARD_ARRAYS.items()
    }


def _render_view(
    world: World, camera: CameraModel, appearance: Appearance, rng: np.random.Generator
) -> tuple[Frame, Viewpoint]:
    """A frame from the first acceptable viewpoint ``rng`` draws (see :data:`MAX_ATTEMPTS`)."""
    random_view = bool(rng.uniform() < RANDOM_VIEW_SHARE)
    for _ in range(MAX_ATTEMPTS):
        view = draw_viewpoint(world, camera, rng, random_view)
        if view is None:
            continue
        frame = render(world, camera, view.position, view.orientation, intensity=False,
                       appearance=appearance)  # fmt: skip
        if acceptable(frame, view):
            return frame, view
    raise InvalidInputError(
        f"{world.name} (seed {world.seed}): no acceptable viewpoint in {MAX_ATTEMPTS} draws"
    )


def acceptable(frame: Frame, view: Viewpoint) -> bool:
    """Whether a frame is kept: the camera is not inside or against an object, and a frame
    looking at a target shows it."""
    if np.mean(frame.depth < NEAR_DEPTH) > NEAR_SHARE:
        return False
    return view.target == 0 or np.mean(frame.instance == view.target) >= MIN_TARGET_SHARE


def _frame_arrays(
    frame: Frame, view: Viewpoint, labels: _Labels, noise: np.random.Generator
) -> dict[str, Any]:
    """One frame in the dataset's labels, its colour image with sensor noise."""
    assert frame.rgb is not None
    class_id = labels.classes[frame.class_id]
    part_id = np.where(class_id > 0, labels.parts[frame.part_id], 0)
    return {
        "rgb": add_colour_noise(frame.rgb, noise, NOISE_SIGMA),
        "class_id": class_id,
        "part_id": part_id,
        "instance": renumbered_instances(frame.instance, class_id > 0),
        "depth": frame.depth,
        "position": frame.position,
        "orientation": frame.orientation,
        "target": view.target,
    }


def renumbered_instances(instance: NDArray[np.integer], targets: NDArray[np.bool_]) -> NDArray:
    """Target pixels' instance ids as 1..k in the order of the world's ids; 0 elsewhere."""
    out = np.zeros(instance.shape, np.uint16)
    ids = np.unique(instance[targets])
    out[targets] = np.searchsorted(ids, instance[targets]) + 1
    return out
