"""Training the learned detector (:mod:`.segnet`) on a detector dataset (:mod:`.shards`).

One loop, read top to bottom: batches drawn by a seeded sampler (a permutation per epoch),
augmented with the data stream's own generator (random crops, horizontal flips that swap
``left`` and ``right`` part names, brightness, contrast and per-channel colour gains, sensor
noise), AdamW with a warm-up and a cosine decay, and the loss

    CE(classes, class weights) + CE(parts on target pixels, part weights) + BCE(seams)

with weights ``1 / sqrt(frequency)`` (normalised to mean 1, at most 10x), so that a wheel
counts although it covers a few percent of a car, and seam pixels weighted by
``sqrt(other pixels / seam pixels)`` (at most 30x) in their binary cross-entropy.

Every ``eval_every`` steps a row goes to ``progress.csv``: the mean training losses since the
last row and, on the held-out shards (the last ``val_fraction`` of them; the last frames when
there is one shard), pixel accuracy and the mean IoU of the classes and of the parts.

``checkpoint.pt`` and ``training-state.pt`` are written at every row, at the end, at the
first step after ``max_minutes``, at ``stop_at`` and on Ctrl-C or SIGTERM (a signal waits for
the step under way). The state holds the weights, the optimiser, every random stream and the
loss sums, so ``resume=True`` continues bit for bit: the same steps, the same weights.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import math
import time
from pathlib import Path
from typing import Any

import numpy as np
import torch
import torch.nn.functional as F  # noqa: N812 - torch's own convention

from seminspect.core.errors import InvalidInputError
from seminspect.core.interrupts import deferred_signals, stop_on_signals
from seminspect.core.io import atomic_write_text
from seminspect.core.rng import make_rng
from seminspect.core.torch_files import torch_threads
from seminspect.perception.segnet import DEFAULT_CHANNELS, SegNet, SegNetConfig
from seminspect.perception.segnet_io import (
    CHECKPOINT_NAME,
    TRAINING_STATE_NAME,
    export_onnx,
    read_training_state,
    save_checkpoint,
    save_training_state,
    state_net,
)
from seminspect.perception.training_data import Batch, DetectorData, augmented, load_data

__all__ = ["DetectorTraining", "TrainResult", "export_onnx", "train_detector"]

EDGE_WEIGHT = 1.0
PROGRESS_FIELDS = (
    "step",
    "wall_s",
    "loss",
    "class_loss",
    "part_loss",
    "edge_loss",
    "lr",
    "pixel_acc",
    "miou",
    "part_miou",
)


@dataclasses.dataclass(frozen=True)
class DetectorTraining:
    """The settings of a run; a resumed run must be given the same."""

    steps: int = 2000
    batch: int = 16
    lr: float = 2e-3
    weight_decay: float = 1e-4
    seed: int = 0
    crop: float = 0.875  # crops' side as a fraction of the image's
    eval_every: int = 100
    val_fraction: float = 0.2
    threads: int = 2
    channels: tuple[int, ...] = DEFAULT_CHANNELS

    def __post_init__(self) -> None:
        for name in ("steps", "batch", "eval_every", "threads"):
            if getattr(self, name) < 1:
                raise InvalidInputError(f"{name} must be >= 1, got {getattr(self, name)}")
        if not (math.isfinite(self.lr) and self.lr > 0):
            raise InvalidInputError(f"lr must be > 0, got {self.lr}")
        if not (0.25 <= self.crop <= 1 and 0 <= self.val_fraction < 1):
            raise InvalidInputError("crop must lie in [0.25, 1] and val_fraction in [0, 1)")

    def as_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self) | {"channels": list(self.channels)}


@dataclasses.dataclass(frozen=True)
class TrainResult:
    """What :func:`train_detector` leaves behind."""

    steps: int
    finished: bool  # False: stopped early (time, stop_at, signal); resume=True continues
    checkpoint: Path
    rows: tuple[dict[str, float], ...]
    wall_s: float  # of this piece
    parameters: int


class _Run:
    """One run's network, optimiser, random streams and loss sums: everything saved."""

    def __init__(self, data: DetectorData, settings: DetectorTraining, net: SegNet):
        self.data, self.settings, self.net = data, settings, net
        self.optimizer = torch.optim.AdamW(
            net.parameters(), lr=settings.lr, weight_decay=settings.weight_decay
        )
        self.sampler = make_rng(settings.seed, "perception", "segnet", "sampler")
        self.augment = make_rng(settings.seed, "perception", "segnet", "augment")
        self.order = np.zeros(0, dtype=np.int64)
        self.cursor = 0
        self.step = 0
        self.sums = np.zeros(4)  # loss, class, part and edge losses since the last row
        self.counted = 0
        self.wall_s = 0.0
        self.rows: list[dict[str, float]] = []
        self.class_weights = torch.from_numpy(data.class_weights)
        self.part_weights = torch.from_numpy(data.part_weights)

    def state(self) -> dict[str, Any]:
        return {
            "net": self.net.config.to_dict(),
            "settings": self.settings.as_dict(),
            "dataset": self.data.fingerprint,
            "model": self.net.state_dict(),
            "optimizer": self.optimizer.state_dict(),
            "torch_rng": torch.get_rng_state(),
            "sampler": self.sampler.bit_generator.state,
            "augment": self.augment.bit_generator.state,
            "order": torch.from_numpy(self.order),
            "cursor": self.cursor,
            "step": self.step,
            "sums": self.sums.tolist(),
            "counted": self.counted,
            "wall_s": self.wall_s,
            "rows": self.rows,
        }

    @classmethod
    def restored(cls, state: dict[str, Any], data: DetectorData, source: Path) -> _Run:
        run = cls(data, DetectorTraining(**state["settings"]), state_net(state, source).train())
        run.optimizer.load_state_dict(state["optimizer"])
        torch.set_rng_state(state["torch_rng"])
        run.sampler.bit_generator.state = state["sampler"]
        run.augment.bit_generator.state = state["augment"]
        run.order = state["order"].numpy().copy()
        run.cursor, run.step, run.counted = state["cursor"], state["step"], state["counted"]
        run.sums, run.wall_s = np.asarray(state["sums"], dtype=float), state["wall_s"]
        run.rows = list(state["rows"])
        return run

    def next_batch(self) -> Batch:
        """The next ``batch`` training frames of the epoch's permutation, augmented."""
        size = min(self.settings.batch, len(self.data.train))
        if self.cursor + size > len(self.order):
            self.order, self.cursor = self.sampler.permutation(len(self.data.train)), 0
        chosen = self.order[self.cursor : self.cursor + size]
        self.cursor += size
        return augmented(self.data, np.sort(chosen), self.settings.crop, self.augment)

    def learning_rate(self) -> float:
        """Linear warm-up over the first 5 % of the steps, then cosine down to 5 %."""
        total, step = self.settings.steps, self.step
        warm = max(1, total // 20)
        if step < warm:
            return self.settings.lr * (step + 1) / warm
        done = (step - warm) / max(1, total - warm)
        return self.settings.lr * (0.05 + 0.95 * 0.5 * (1 + math.cos(math.pi * done)))

    def train_step(self) -> None:
        batch = self.next_batch()
        lr = self.learning_rate()
        for group in self.optimizer.param_groups:
            group["lr"] = lr
        classes, parts, edges = self.net(torch.from_numpy(batch.images))
        losses = self.losses(classes, parts, edges, batch)
        self.optimizer.zero_grad(set_to_none=True)
        losses[0].backward()
        self.optimizer.step()
        self.sums += np.array([v.item() for v in losses])
        self.counted += 1
        self.step += 1

    def losses(
        self, classes: torch.Tensor, parts: torch.Tensor, edges: torch.Tensor, batch: Batch
    ) -> tuple[torch.Tensor, ...]:
        target = torch.from_numpy(batch.classes).long()
        class_loss = F.cross_entropy(classes, target, weight=self.class_weights)
        on_target = target > 0
        if bool(on_target.any()):
            part_target = torch.from_numpy(batch.parts).long().masked_fill(~on_target, -100)
            part_loss = F.cross_entropy(parts, part_target, weight=self.part_weights)
        else:
            part_loss = parts.sum() * 0.0
        seams = torch.from_numpy(batch.edges).float()[:, None]
        positive = torch.tensor(self.data.seam_weight)  # seams are a sliver of the image
        edge_loss = F.binary_cross_entropy_with_logits(edges, seams, pos_weight=positive)
        total = class_loss + part_loss + EDGE_WEIGHT * edge_loss
        return total, class_loss, part_loss, edge_loss

    def progress_row(self) -> dict[str, float]:
        means = self.sums / max(self.counted, 1)
        row = {"step": float(self.step), "wall_s": self.wall_s}
        row |= dict(zip(PROGRESS_FIELDS[2:6], means.tolist(), strict=True))
        row["lr"] = self.learning_rate()
        row |= validation_metrics(self.net, self.data)
        self.sums, self.counted = np.zeros(4), 0
        self.rows.append(row)
        return row


def validation_metrics(net: SegNet, data: DetectorData, chunk: int = 8) -> dict[str, float]:
    """Pixel accuracy and the mean IoU of classes and of parts (on target pixels, ``none``
    left out) over the held-out frames; NaN without any."""
    frames = data.val
    if not len(frames):
        return {"pixel_acc": math.nan, "miou": math.nan, "part_miou": math.nan}
    n_classes, n_parts = len(data.info.classes), len(data.info.parts)
    class_confusion = np.zeros((n_classes, n_classes), dtype=np.int64)
    part_confusion = np.zeros((n_parts, n_parts), dtype=np.int64)
    net.eval()
    with torch.no_grad():
        for first in range(0, len(frames), chunk):
            index = frames[first : first + chunk]
            images = data.rgb[index].transpose(0, 3, 1, 2).astype(np.float32) / 255
            classes, parts, _ = net(torch.from_numpy(images))
            guess, truth = classes.argmax(1).numpy(), data.classes[index]
            class_confusion += _confusion(truth, guess, n_classes)
            both = (truth > 0) & (guess > 0)
            part_confusion += _confusion(
                data.parts[index][both], parts.argmax(1).numpy()[both], n_parts
            )
    net.train()
    accuracy = np.trace(class_confusion) / max(class_confusion.sum(), 1)
    return {
        "pixel_acc": float(accuracy),
        "miou": _mean_iou(class_confusion),
        "part_miou": _mean_iou(part_confusion, first=1),
    }


def _confusion(truth: np.ndarray, guess: np.ndarray, count: int) -> np.ndarray:
    key = truth.astype(np.int64).ravel() * count + guess.astype(np.int64).ravel()
    return np.bincount(key, minlength=count * count).reshape(count, count)


def _mean_iou(confusion: np.ndarray, first: int = 0) -> float:
    """The mean IoU of the labels from ``first`` on that occur in the truth or the guesses;
    NaN when none do."""
    hits = np.diag(confusion)
    union = confusion.sum(0) + confusion.sum(1) - hits
    hits, union = hits[first:], union[first:]
    present = union > 0
    return float(np.mean(hits[present] / union[present])) if present.any() else math.nan


def train_detector(
    dataset_dir: str | Path,
    out_dir: str | Path,
    *,
    steps: int = 2000,
    batch: int = 16,
    lr: float = 2e-3,
    seed: int = 0,
    max_minutes: float | None = None,
    resume: bool = False,
    stop_at: int | None = None,
    **settings: Any,
) -> TrainResult:
    """Train (or with ``resume`` continue) the detector network on ``dataset_dir``, writing
    ``progress.csv``, ``checkpoint.pt`` and ``training-state.pt`` into ``out_dir``.

    ``settings``: the other fields of :class:`DetectorTraining` (``eval_every``, ``threads``,
    ``channels``, ...). The run stops cleanly, its state saved, at the first step boundary after
    ``max_minutes``, after step ``stop_at``, or on Ctrl-C or SIGTERM (re-raised once saved).
    """
    config = DetectorTraining(steps=steps, batch=batch, lr=lr, seed=seed, **settings)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    with torch_threads(config.threads):
        data = load_data(dataset_dir, config.val_fraction)
        run = _resumed(out, data, config) if resume else _fresh(data, config)
        return _drive(run, out, max_minutes, stop_at)


def _fresh(data: DetectorData, config: DetectorTraining) -> _Run:
    torch.manual_seed(int(make_rng(config.seed, "perception", "segnet", "init").integers(2**62)))
    net_config = SegNetConfig(data.info.classes, data.info.parts, data.info.shape, config.channels)
    return _Run(data, config, SegNet(net_config).train())


def _resumed(out: Path, data: DetectorData, config: DetectorTraining) -> _Run:
    source = out / TRAINING_STATE_NAME
    state = read_training_state(source)
    saved = state.get("settings")
    if saved != config.as_dict():
        differ = sorted(k for k, v in config.as_dict().items() if (saved or {}).get(k) != v)
        raise InvalidInputError(f"{source}: resume with the run's own settings ({differ} differ)")
    if state.get("dataset") != data.fingerprint:
        raise InvalidInputError(f"{source}: the run was trained on another dataset")
    return _Run.restored(state, data, source)


def _drive(run: _Run, out: Path, max_minutes: float | None, stop_at: int | None) -> TrainResult:
    """Steps until the budget, the time limit or ``stop_at``; saving as documented."""
    start, before = time.perf_counter(), run.wall_s
    limit = None if max_minutes is None else 60 * max_minutes
    with stop_on_signals():
        try:
            while run.step < run.settings.steps:
                with deferred_signals():  # a stop waits for the step's end, where all is whole
                    run.train_step()
                    run.wall_s = before + time.perf_counter() - start
                    if run.step % run.settings.eval_every == 0 or run.step == run.settings.steps:
                        run.progress_row()
                        _save(run, out)
                elapsed = time.perf_counter() - start
                if (limit is not None and elapsed >= limit) or run.step == stop_at:
                    break
        except KeyboardInterrupt:  # raised between steps only: the state is whole
            _save(run, out)
            raise
        _save(run, out)
    return TrainResult(
        steps=run.step,
        finished=run.step >= run.settings.steps,
        checkpoint=out / CHECKPOINT_NAME,
        rows=tuple(run.rows),
        wall_s=time.perf_counter() - start,
        parameters=sum(p.numel() for p in run.net.parameters()),
    )


def _save(run: _Run, out: Path) -> None:
    with deferred_signals():  # a second Ctrl-C must not cut the save short
        save_training_state(out / TRAINING_STATE_NAME, run.state())
        save_checkpoint(out / CHECKPOINT_NAME, run.net, run.step, run.settings.as_dict())
        _write_progress(out / "progress.csv", run.rows)


def _write_progress(path: Path, rows: list[dict[str, float]]) -> None:
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(PROGRESS_FIELDS)
    for row in rows:
        writer.writerow(_cell(row[name], name) for name in PROGRESS_FIELDS)
    atomic_write_text(path, buffer.getvalue())


def _cell(value: float, name: str) -> str:
    if name == "step":
        return str(int(value))
    return f"{value:.6g}" if math.isfinite(value) else ""
