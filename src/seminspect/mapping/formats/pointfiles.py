"""Point-cloud files users bring: PLY, PCD and NPZ with per-point embeddings or labels.

Conventions for semantic fields (the same in every format):

- coordinates are the fields ``x``, ``y``, ``z``;
- a class label is an integer field ``label``; label names come from header comments
  ``label <id> <name>`` (PLY ``comment`` lines, PCD ``#`` lines), an NPZ array ``label_names``
  indexed by id, or the caller;
- an embedding is the PCD field ``embedding`` with ``COUNT d``, the PLY properties
  ``emb_0 .. emb_{d-1}`` or the NPZ array ``embeddings``.

PCD data may be ``ascii``, ``binary`` or ``binary_compressed`` (LZF, as PCL writes it). Every
malformed file (bad header, truncated data, wrong sizes, NaN coordinates) raises
:class:`FileFormatError` with one line naming the problem.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numba
import numpy as np
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.mapping.semantic_cloud import read_npz

#: Refuse point files larger than this before reading them.
MAX_POINT_FILE_BYTES = 4 << 30
_LABEL_COMMENT = re.compile(r"^label\s+(-?\d+)\s+(\S.*?)\s*$")


@dataclass
class PointData:
    """Points read from a file, with the semantic fields it carries."""

    points: NDArray[np.float64]
    embeddings: NDArray[np.float32] | None = None
    labels: NDArray[np.int64] | None = None
    label_names: dict[int, str] = field(default_factory=dict)


def load_point_file(path: str | Path) -> PointData:
    """Read a ``.ply``, ``.pcd``, ``.npz``, ``.las`` or ``.laz`` point file (by extension)."""
    source = Path(path)
    if source.is_dir():
        raise FileFormatError(f"{source}: is a directory, expected a point file")
    if source.suffix.lower() in (".las", ".laz"):
        from seminspect.mapping.formats.las import read_las  # noqa: PLC0415 - needs laspy

        return read_las(source)  # type: ignore[return-value] # PointData's fields and more
    reader = {".ply": read_ply, ".pcd": read_pcd, ".npz": read_point_npz}.get(source.suffix.lower())
    if reader is None:
        raise FileFormatError(
            f"{source}: unsupported point file type {source.suffix!r} (use ply, pcd, npz, las, laz)"
        )
    return reader(source)


def _read_bytes(source: Path) -> bytes:
    if not source.is_file():
        raise FileFormatError(f"{source}: no such file")
    size = source.stat().st_size
    if size > MAX_POINT_FILE_BYTES:
        raise FileFormatError(f"{source}: {size} bytes is larger than the point-file limit")
    return source.read_bytes()


def _split_header(source: Path, raw: bytes, last_key: bytes) -> tuple[list[str], bytes]:
    """Header lines up to and including the line starting with ``last_key``, and the body."""
    lines: list[str] = []
    offset = 0
    while True:
        end = raw.find(b"\n", offset)
        if end < 0:
            raise FileFormatError(f"{source}: header never ends (no {last_key.decode()} line)")
        line = raw[offset:end].rstrip(b"\r")
        offset = end + 1
        try:
            lines.append(line.decode("ascii").strip())
        except UnicodeDecodeError:
            raise FileFormatError(f"{source}: header is not ASCII text") from None
        if line.startswith(last_key):
            return lines, raw[offset:]
        if len(lines) > 10_000:
            raise FileFormatError(f"{source}: header longer than 10,000 lines")


def _label_names(comments: list[str]) -> dict[int, str]:
    names = {}
    for comment in comments:
        match = _LABEL_COMMENT.match(comment)
        if match:
            names[int(match.group(1))] = match.group(2)
    return names


def _to_point_data(
    source: Path,
    fields: dict[str, NDArray],
    label_names: dict[int, str],
    embedding_columns: NDArray | None,
) -> PointData:
    missing = [axis for axis in "xyz" if axis not in fields]
    if missing:
        raise FileFormatError(f"{source}: no {', '.join(missing)} field (need x, y, z)")
    points = np.column_stack([fields[axis].astype(np.float64) for axis in "xyz"])
    bad = int(np.count_nonzero(~np.all(np.isfinite(points), axis=1)))
    if bad:
        raise FileFormatError(f"{source}: {bad} points have NaN or infinite coordinates")
    if points.shape[0] == 0:
        raise FileFormatError(f"{source}: the file holds no points")
    labels = None
    if "label" in fields:
        raw_labels = fields["label"]
        if not np.all(np.isfinite(raw_labels)) or np.any(raw_labels != np.round(raw_labels)):
            raise FileFormatError(f"{source}: labels must be whole numbers")
        labels = raw_labels.astype(np.int64)
    embeddings = None
    if embedding_columns is not None:
        embeddings = np.asarray(embedding_columns, dtype=np.float32).reshape(points.shape[0], -1)
        if not np.all(np.isfinite(embeddings)):
            raise FileFormatError(f"{source}: embeddings contain NaN or infinite values")
    return PointData(points, embeddings, labels, label_names)


# --- PLY -----------------------------------------------------------------------------------

_PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}  # fmt: skip


@dataclass
class _PlyElement:
    name: str
    count: int
    properties: list[tuple[str, str]] = field(default_factory=list)
    has_list: bool = False


def _ply_header(source: Path, lines: list[str]) -> tuple[str, list[_PlyElement], list[str]]:
    if not lines or lines[0] != "ply":
        raise FileFormatError(f"{source}: not a PLY file (first line is not 'ply')")
    encoding = None
    elements: list[_PlyElement] = []
    comments: list[str] = []
    for line in lines[1:-1]:
        words = line.split()
        if not words:
            continue
        keyword = words[0]
        if keyword == "format" and len(words) == 3:
            encoding = words[1]
        elif keyword in ("comment", "obj_info"):
            comments.append(line[len(keyword) :].strip())
        elif keyword == "element" and len(words) == 3 and words[2].isdigit():
            elements.append(_PlyElement(words[1], int(words[2])))
        elif keyword == "property" and elements and len(words) == 3 and words[1] in _PLY_TYPES:
            elements[-1].properties.append((words[2], _PLY_TYPES[words[1]]))
        elif keyword == "property" and elements and len(words) == 5 and words[1] == "list":
            elements[-1].has_list = True
        else:
            raise FileFormatError(f"{source}: bad PLY header line {line!r}")
    if encoding not in ("ascii", "binary_little_endian", "binary_big_endian"):
        raise FileFormatError(f"{source}: unknown PLY format {encoding!r}")
    return encoding, elements, comments


def read_ply(path: str | Path) -> PointData:
    """Read the ``vertex`` element of an ASCII or binary PLY file."""
    source = Path(path)
    lines, body = _split_header(source, _read_bytes(source), b"end_header")
    encoding, elements, comments = _ply_header(source, lines)
    names = [element.name for element in elements]
    if "vertex" not in names:
        raise FileFormatError(f"{source}: PLY file has no vertex element")
    position = names.index("vertex")
    vertex = elements[position]
    if vertex.has_list:
        raise FileFormatError(f"{source}: list properties on vertices are not supported")
    if encoding == "ascii":
        table = _ply_ascii_vertices(source, body, elements, position)
    else:
        table = _ply_binary_vertices(source, body, elements, position, encoding)
    fields = {name: table[name] for name, _ in vertex.properties}
    embedding_names = sorted(
        (name for name in fields if re.fullmatch(r"emb_\d+", name)), key=lambda n: int(n[4:])
    )
    if embedding_names and embedding_names != [f"emb_{i}" for i in range(len(embedding_names))]:
        raise FileFormatError(f"{source}: embedding properties must be emb_0 .. emb_(d-1)")
    columns = (
        np.column_stack([fields[name] for name in embedding_names]) if embedding_names else None
    )
    return _to_point_data(source, fields, _label_names(comments), columns)


def _ply_ascii_vertices(
    source: Path, body: bytes, elements: list[_PlyElement], position: int
) -> dict[str, NDArray]:
    vertex = elements[position]
    skip = sum(element.count for element in elements[:position])
    rows = body.decode("ascii", errors="replace").splitlines()
    while rows and not rows[-1].strip():  # a trailing blank line is no row
        rows.pop()
    declared = sum(element.count for element in elements)
    if len(rows) != declared:  # one line per row: more lines are points the header hides
        raise FileFormatError(
            f"{source}: the header says {vertex.count} vertices ({declared} rows in all), "
            f"the file holds {len(rows)} rows"
        )
    rows = rows[skip : skip + vertex.count]
    width = len(vertex.properties)
    try:
        values = np.array([row.split() for row in rows], dtype=np.float64)
    except ValueError:
        raise FileFormatError(f"{source}: vertex rows are not {width} numbers each") from None
    if values.shape != (vertex.count, width) and not (vertex.count == 0 and values.size == 0):
        raise FileFormatError(f"{source}: vertex rows are not {width} numbers each")
    values = values.reshape(vertex.count, width)
    return {name: values[:, i] for i, (name, _) in enumerate(vertex.properties)}


def _record_size(element: _PlyElement) -> int:
    return sum(np.dtype(kind).itemsize for _, kind in element.properties)


def _ply_binary_vertices(
    source: Path, body: bytes, elements: list[_PlyElement], position: int, encoding: str
) -> dict[str, NDArray]:
    order = "<" if encoding == "binary_little_endian" else ">"
    vertex = elements[position]
    for element in elements[:position]:
        if element.has_list:
            raise FileFormatError(
                f"{source}: element {element.name!r} with list properties precedes the vertices"
            )
    offset = sum(element.count * _record_size(element) for element in elements[:position])
    dtype = np.dtype([(name, order + kind) for name, kind in vertex.properties])
    needed = offset + vertex.count * dtype.itemsize
    if len(body) < needed:
        raise FileFormatError(
            f"{source}: truncated: vertex data needs {needed} bytes, the file has {len(body)}"
        )
    surplus = len(body) - needed
    # when the vertices end the body, data for one more is a vertex the header hides (padding
    # shorter than a vertex, as a trailing newline, holds none)
    if position == len(elements) - 1 and surplus >= dtype.itemsize > 0:
        raise FileFormatError(
            f"{source}: the header says {vertex.count} vertices, the data holds "
            f"{vertex.count + surplus // dtype.itemsize}"
        )
    table = np.frombuffer(body, dtype=dtype, count=vertex.count, offset=offset)
    return {name: table[name] for name, _ in vertex.properties}


# --- PCD -----------------------------------------------------------------------------------

_PCD_KINDS = {
    (kind, size): f"{kind.lower()}{size}"
    for kind, size in [("F", 4), ("F", 8), *[(k, s) for k in "IU" for s in (1, 2, 4, 8)]]
}


@dataclass(frozen=True)
class _PcdHeader:
    names: list[str]
    kinds: list[str]
    counts: list[int]
    points: int
    data: str
    comments: list[str]


def _pcd_header(source: Path, lines: list[str]) -> _PcdHeader:
    entries: dict[str, list[str]] = {}
    comments = []
    for line in lines:
        if line.startswith("#"):
            comments.append(line[1:].strip())
        elif line:
            key, *values = line.split()
            entries[key.upper()] = values
    try:
        names = entries["FIELDS"]
        sizes = [int(s) for s in entries["SIZE"]]
        types = entries["TYPE"]
        counts = [int(c) for c in entries.get("COUNT", ["1"] * len(names))]
        points = int(entries["POINTS"][0])
        data = entries["DATA"][0]
    except KeyError as exc:
        raise FileFormatError(f"{source}: PCD header lacks {exc.args[0]}") from None
    except (ValueError, IndexError):
        raise FileFormatError(f"{source}: PCD header has a malformed SIZE/COUNT/POINTS") from None
    if not (len(names) == len(sizes) == len(types) == len(counts)):
        raise FileFormatError(f"{source}: PCD FIELDS, SIZE, TYPE and COUNT differ in length")
    kinds = []
    for name, kind, size in zip(names, types, sizes, strict=True):
        if (kind, size) not in _PCD_KINDS:
            raise FileFormatError(
                f"{source}: field {name!r} has unsupported TYPE {kind} SIZE {size}"
            )
        kinds.append(_PCD_KINDS[(kind, size)])
    if points < 0 or any(count < 1 for count in counts):
        raise FileFormatError(f"{source}: negative POINTS or COUNT below 1")
    _check_pcd_size(source, entries, points)
    return _PcdHeader(names, kinds, counts, points, data, comments)


def _check_pcd_size(source: Path, entries: dict[str, list[str]], points: int) -> None:
    """PCL requires ``POINTS == WIDTH * HEIGHT``; a file that disagrees lost points or rows."""
    if "WIDTH" not in entries or "HEIGHT" not in entries:
        return
    try:
        width, height = int(entries["WIDTH"][0]), int(entries["HEIGHT"][0])
    except (ValueError, IndexError):
        raise FileFormatError(f"{source}: PCD header has a malformed WIDTH/HEIGHT") from None
    if width * height != points:
        raise FileFormatError(
            f"{source}: WIDTH {width} x HEIGHT {height} is {width * height} points, "
            f"POINTS says {points}"
        )


def read_pcd(path: str | Path) -> PointData:
    """Read a PCL ``.pcd`` file (v0.7; ascii, binary or binary_compressed)."""
    source = Path(path)
    lines, body = _split_header(source, _read_bytes(source), b"DATA")
    header = _pcd_header(source, lines)
    decoders = {"ascii": _pcd_ascii, "binary": _pcd_binary, "binary_compressed": _pcd_compressed}
    decoder = decoders.get(header.data)
    if decoder is None:
        raise FileFormatError(f"{source}: unknown PCD DATA encoding {header.data!r}")
    columns = decoder(source, header, body)
    fields = {name: column for name, column in columns.items() if column.ndim == 1}
    embedding = columns.get("embedding")
    return _to_point_data(source, fields, _label_names(header.comments), embedding)


def _pcd_dtype(header: _PcdHeader) -> np.dtype:
    return np.dtype(
        [
            (name, "<" + kind, (count,)) if count > 1 else (name, "<" + kind)
            for name, kind, count in zip(header.names, header.kinds, header.counts, strict=True)
        ]
    )


def _pcd_ascii(source: Path, header: _PcdHeader, body: bytes) -> dict[str, NDArray]:
    width = sum(header.counts)
    try:
        values = np.array(body.decode("ascii").split(), dtype=np.float64)
    except (UnicodeDecodeError, ValueError):
        raise FileFormatError(
            f"{source}: PCD ascii data holds something other than numbers"
        ) from None
    if values.size != header.points * width:
        raise FileFormatError(
            f"{source}: expected {header.points} points of {width} values, "
            f"found {values.size} values"
        )
    table = values.reshape(header.points, width)
    out, start = {}, 0
    for name, count in zip(header.names, header.counts, strict=True):
        block = table[:, start : start + count]
        out[name] = block[:, 0] if count == 1 else block
        start += count
    return out


def _pcd_binary(source: Path, header: _PcdHeader, body: bytes) -> dict[str, NDArray]:
    dtype = _pcd_dtype(header)
    needed = header.points * dtype.itemsize
    if len(body) < needed:
        raise FileFormatError(
            f"{source}: truncated: {header.points} points need {needed} bytes, found {len(body)}"
        )
    # padding shorter than one point is no point; more is data the header does not count
    if dtype.itemsize and len(body) - needed >= dtype.itemsize:
        raise FileFormatError(
            f"{source}: POINTS says {header.points}, the data holds "
            f"{len(body) // dtype.itemsize} points"
        )
    table = np.frombuffer(body, dtype=dtype, count=header.points)
    return {name: table[name] for name in header.names}


def _pcd_compressed(source: Path, header: _PcdHeader, body: bytes) -> dict[str, NDArray]:
    if len(body) < 8:
        raise FileFormatError(f"{source}: truncated: binary_compressed data has no size words")
    compressed_size, raw_size = (int(v) for v in np.frombuffer(body, "<u4", count=2))
    dtype = _pcd_dtype(header)
    if raw_size != header.points * dtype.itemsize:
        raise FileFormatError(
            f"{source}: compressed block unpacks to {raw_size} bytes, "
            f"{header.points} points need {header.points * dtype.itemsize}"
        )
    if len(body) < 8 + compressed_size:
        raise FileFormatError(f"{source}: truncated: compressed block is shorter than announced")
    raw = lzf_decompress(np.frombuffer(body, np.uint8, count=compressed_size, offset=8), raw_size)
    if raw is None:
        raise FileFormatError(f"{source}: corrupt LZF data in the binary_compressed block")
    # PCL stores compressed data field by field: all x, then all y, ...
    out, start = {}, 0
    for name, kind, count in zip(header.names, header.kinds, header.counts, strict=True):
        length = header.points * count * np.dtype(kind).itemsize
        column = np.frombuffer(raw[start : start + length].tobytes(), "<" + kind)
        out[name] = column if count == 1 else column.reshape(header.points, count)
        start += length
    return out


def lzf_decompress(data: NDArray[np.uint8], size: int) -> NDArray[np.uint8] | None:
    """Decompress an LZF stream into exactly ``size`` bytes, or ``None`` if it is corrupt."""
    out = np.empty(size, dtype=np.uint8)
    written = _lzf_kernel(np.ascontiguousarray(data), out)
    return out if written == size else None


@numba.njit(cache=True)
def _lzf_kernel(src: NDArray[np.uint8], out: NDArray[np.uint8]) -> int:  # pragma: no cover
    # LZF: a control byte below 32 starts a literal run of ctrl+1 bytes; otherwise its top three
    # bits (plus an extension byte when all set) give a match length and the rest a back offset.
    ip, op, n, m = 0, 0, src.size, out.size
    while ip < n:
        ctrl = np.int64(src[ip])
        ip += 1
        if ctrl < 32:
            length = ctrl + 1
            if ip + length > n or op + length > m:
                return -1
            out[op : op + length] = src[ip : ip + length]
            ip += length
            op += length
            continue
        length = ctrl >> 5
        ref = op - ((ctrl & 0x1F) << 8) - 1
        if length == 7:
            if ip >= n:
                return -1
            length += np.int64(src[ip])
            ip += 1
        if ip >= n:
            return -1
        ref -= np.int64(src[ip])
        ip += 1
        length += 2
        if ref < 0 or op + length > m:
            return -1
        for k in range(length):  # byte by byte: the source may overlap the output
            out[op + k] = out[ref + k]
        op += length
    return op


# --- NPZ -----------------------------------------------------------------------------------


def read_point_npz(path: str | Path) -> PointData:
    """An ``.npz`` with ``points`` and ``embeddings`` or ``labels`` (+ ``label_names``)."""
    source = Path(path)
    arrays = read_npz(source)
    if "points" not in arrays:
        raise FileFormatError(f"{source}: no 'points' array")
    points = arrays["points"]
    if points.ndim != 2 or points.shape[1] != 3 or not np.issubdtype(points.dtype, np.number):
        raise FileFormatError(f"{source}: 'points' must be an (N, 3) numeric array")
    fields = {axis: points[:, i] for i, axis in enumerate("xyz")}
    if "labels" in arrays:
        labels = arrays["labels"].reshape(-1)
        if labels.shape[0] != points.shape[0] or not np.issubdtype(labels.dtype, np.number):
            raise FileFormatError(f"{source}: 'labels' must hold one number per point")
        fields["label"] = labels
    embeddings = arrays.get("embeddings")
    if embeddings is not None and (
        embeddings.ndim != 2
        or embeddings.shape[0] != points.shape[0]
        or not np.issubdtype(embeddings.dtype, np.number)
    ):
        raise FileFormatError(f"{source}: 'embeddings' must be an (N, d) numeric array")
    names = {}
    if "label_names" in arrays:
        names = {i: str(name) for i, name in enumerate(arrays["label_names"].reshape(-1)) if name}
    return _to_point_data(source, fields, names, embeddings)


def label_names_from_text(spec: str) -> dict[int, str]:
    """Parse ``"0=ground,1=car"`` into ``{0: "ground", 1: "car"}``."""
    names = {}
    for item in filter(None, (part.strip() for part in spec.split(","))):
        key, sep, name = item.partition("=")
        if not sep or not key.strip().lstrip("-").isdigit() or not name.strip():
            raise InvalidInputError(f"label names look like '0=ground,1=car', got {item!r}")
        names[int(key)] = name.strip()
    return names
