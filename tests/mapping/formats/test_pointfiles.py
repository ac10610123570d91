import numpy as np
import pytest

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.mapping.formats.pointfiles import (
    label_names_from_text,
    load_point_file,
    lzf_decompress,
)

POINTS = np.array([[0.0, 1.0, 2.0], [3.0, 4.0, 5.5], [-1.0, -2.0, -3.0]], dtype=np.float32)
LABELS = np.array([1, 0, 1], dtype=np.int32)
EMBEDDINGS = np.arange(6, dtype=np.float32).reshape(3, 2) / 10


def _ply(encoding: str) -> bytes:
    header = [
        "ply",
        f"format {encoding} 1.0",
        "comment label 0 grass",
        "comment label 1 car",
        "element vertex 3",
        "property float x",
        "property float y",
        "property float z",
        "property int label",
        "property float emb_0",
        "property float emb_1",
        "element face 0",
        "property list uchar int vertex_indices",
        "end_header",
    ]
    head = ("\n".join(header) + "\n").encode()
    if encoding == "ascii":
        rows = [
            f"{p[0]} {p[1]} {p[2]} {lab} {e[0]} {e[1]}"
            for p, lab, e in zip(POINTS, LABELS, EMBEDDINGS, strict=True)
        ]
        return head + ("\n".join(rows) + "\n").encode()
    dtype = np.dtype([("p", "<f4", 3), ("label", "<i4"), ("e", "<f4", 2)])
    table = np.zeros(3, dtype)
    table["p"], table["label"], table["e"] = POINTS, LABELS, EMBEDDINGS
    return head + table.tobytes()


def _pcd(data: str) -> bytes:
    header = [
        "# .PCD v0.7",
        "# label 1 car",
        "VERSION 0.7",
        "FIELDS x y z label embedding",
        "SIZE 4 4 4 4 4",
        "TYPE F F F U F",
        "COUNT 1 1 1 1 2",
        "WIDTH 3",
        "HEIGHT 1",
        "VIEWPOINT 0 0 0 1 0 0 0",
        "POINTS 3",
        f"DATA {data}",
    ]
    head = ("\n".join(header) + "\n").encode()
    if data == "ascii":
        rows = [
            " ".join(str(v) for v in (*p, lab, *e))
            for p, lab, e in zip(POINTS, LABELS, EMBEDDINGS, strict=True)
        ]
        return head + ("\n".join(rows) + "\n").encode()
    columns = [POINTS[:, 0], POINTS[:, 1], POINTS[:, 2], LABELS.astype("<u4"), EMBEDDINGS]
    if data == "binary":
        dtype = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("l", "<u4"), ("e", "<f4", 2)])
        table = np.zeros(3, dtype)
        for name, column in zip(dtype.names, columns, strict=True):
            table[name] = column
        return head + table.tobytes()
    raw = b"".join(np.ascontiguousarray(c).tobytes() for c in columns)
    packed = _lzf_literals(raw)
    return head + np.array([len(packed), len(raw)], "<u4").tobytes() + packed


def _lzf_literals(raw: bytes) -> bytes:
    """A valid LZF stream made only of literal runs (at most 32 bytes each)."""
    out = bytearray()
    for start in range(0, len(raw), 32):
        chunk = raw[start : start + 32]
        out += bytes([len(chunk) - 1]) + chunk
    return bytes(out)


@pytest.mark.parametrize(
    ("suffix", "content"),
    [
        (".ply", _ply("ascii")),
        (".ply", _ply("binary_little_endian")),
        (".pcd", _pcd("ascii")),
        (".pcd", _pcd("binary")),
        (".pcd", _pcd("binary_compressed")),
    ],
)
def test_round_trip_of_every_encoding(tmp_path, suffix, content) -> None:
    path = tmp_path / f"cloud{suffix}"
    path.write_bytes(content)
    data = load_point_file(path)
    np.testing.assert_allclose(data.points, POINTS)
    assert data.labels.tolist() == LABELS.tolist()
    np.testing.assert_allclose(data.embeddings, EMBEDDINGS, atol=1e-6)
    assert data.label_names[1] == "car"


def test_npz_with_labels_and_names(tmp_path) -> None:
    path = tmp_path / "cloud.npz"
    np.savez(path, points=POINTS, labels=LABELS, label_names=np.array(["grass", "car"]))
    data = load_point_file(path)
    assert data.embeddings is None
    assert data.label_names == {0: "grass", 1: "car"}


def test_lzf_back_references() -> None:
    # "abcabcabc": 3 literals, then a match of length 6 at distance 3
    stream = np.frombuffer(bytes([2]) + b"abc" + bytes([(4 << 5) | 0, 2]), np.uint8)
    assert lzf_decompress(stream, 9).tobytes() == b"abcabcabc"
    assert lzf_decompress(stream, 10) is None  # wrong announced size
    assert lzf_decompress(np.frombuffer(bytes([(1 << 5), 9]), np.uint8), 3) is None


def test_real_lzf_pcd_matches_reference(shared_data) -> None:
    data = load_point_file(shared_data / "pcl_outdoor" / "car6.pcd")
    reference = np.load(shared_data / "pcl_outdoor" / "pcl_outdoor_xyz.npz")["car6"]
    np.testing.assert_array_equal(data.points.astype(np.float32), reference)
    samp = load_point_file(shared_data / "isprs_filtertest_terrain" / "samp11-utm.pcd")
    assert samp.points.shape == (38010, 3)
    lamppost = load_point_file(shared_data / "pcl_outdoor" / "lamppost.pcd")  # ascii
    assert lamppost.points.shape == (1771, 3)


@pytest.mark.parametrize(
    ("name", "content", "message"),
    [
        ("a.ply", _ply("binary_little_endian")[:-7], "truncated"),
        ("b.ply", b"plx\nend_header\n", "not a PLY"),
        ("c.ply", _ply("ascii").replace(b"element vertex 3", b"element vertex 4"), "rows"),
        ("d.ply", _ply("ascii").replace(b"format ascii", b"format weird"), "format"),
        ("e.pcd", _pcd("binary")[:-5], "truncated"),
        (
            "f.pcd",
            _pcd("ascii").replace(b"POINTS 3", b"POINTS 4").replace(b"WIDTH 3", b"WIDTH 4"),
            "expected 4 points",
        ),
        ("g.pcd", _pcd("ascii").replace(b"SIZE 4 4 4 4 4", b"SIZE 4 4 4 4"), "differ"),
        ("h.pcd", _pcd("ascii").replace(b"0.0 1.0 2.0", b"nan 1.0 2.0"), "NaN"),
        ("i.pcd", _pcd("binary_compressed")[:-3], "truncated"),
        ("j.pcd", _pcd("ascii").replace(b"DATA ascii", b"DATA zip"), "encoding"),
        ("k.pcd", b"VERSION 0.7\n", "header never ends"),
        ("l.xyz", b"1 2 3\n", "unsupported"),
    ],
)
def test_malformed_files_give_one_clear_error(tmp_path, name, content, message) -> None:
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(FileFormatError, match=message) as caught:
        load_point_file(path)
    assert "\n" not in str(caught.value)


def test_corrupt_lzf_block(tmp_path) -> None:
    content = bytearray(_pcd("binary_compressed"))
    first_control = content.index(b"DATA binary_compressed\n") + len("DATA binary_compressed\n") + 8
    content[first_control] = 0xFF  # a back reference before the start of the output
    path = tmp_path / "corrupt.pcd"
    path.write_bytes(bytes(content))
    with pytest.raises(FileFormatError, match="corrupt LZF"):
        load_point_file(path)


def test_label_names_text() -> None:
    assert label_names_from_text("0=grass, 1=car") == {0: "grass", 1: "car"}
    with pytest.raises(InvalidInputError):
        label_names_from_text("grass")


def _vertex_ply(encoding: str, declared: int, rows: int) -> bytes:
    """A vertex-only PLY whose header declares ``declared`` vertices over ``rows`` of data."""
    header = f"ply\nformat {encoding} 1.0\nelement vertex {declared}\n"
    header += "property float x\nproperty float y\nproperty float z\nend_header\n"
    points = np.arange(3 * rows, dtype=np.float32).reshape(rows, 3)
    if encoding == "ascii":
        return (header + "".join(f"{x} {y} {z}\n" for x, y, z in points)).encode()
    return header.encode() + points.astype("<f4" if "little" in encoding else ">f4").tobytes()


@pytest.mark.parametrize("encoding", ["ascii", "binary_little_endian", "binary_big_endian"])
def test_a_ply_hiding_rows_behind_its_header_is_refused(tmp_path, encoding) -> None:
    path = tmp_path / "cloud.ply"
    path.write_bytes(_vertex_ply(encoding, 6900, 7000))
    with pytest.raises(FileFormatError, match=r"cloud\.ply: the header says 6900 vertices"):
        load_point_file(path)
    with pytest.raises(FileFormatError, match="7000") as caught:
        load_point_file(path)
    assert "\n" not in str(caught.value)
    path.write_bytes(_vertex_ply(encoding, 7000, 7000) + b"\n")  # a trailing newline is no row
    assert load_point_file(path).points.shape == (7000, 3)


def test_pcd_sizes_that_disagree_are_refused(tmp_path) -> None:
    path = tmp_path / "cloud.pcd"
    path.write_bytes(_pcd("ascii").replace(b"WIDTH 3", b"WIDTH 4"))
    with pytest.raises(FileFormatError, match=r"WIDTH 4 x HEIGHT 1 is 4 points, POINTS says 3"):
        load_point_file(path)
    # POINTS 2 over three points of binary data: the third would be dropped
    hidden = _pcd("binary").replace(b"POINTS 3", b"POINTS 2").replace(b"WIDTH 3", b"WIDTH 2")
    path.write_bytes(hidden)
    with pytest.raises(FileFormatError, match=r"cloud\.pcd: POINTS says 2, the data holds 3"):
        load_point_file(path)
    path.write_bytes(_pcd("binary") + b"\n")  # padding shorter than a point holds none
    np.testing.assert_allclose(load_point_file(path).points, POINTS)
