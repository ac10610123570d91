"""LAS and LAZ files written here with laspy itself, read by ``mapping.formats.las``."""

import laspy
import numpy as np
import pytest
from laspy.vlrs.known import GeoKeyDirectoryVlr, GeoKeyEntryStruct, WktCoordinateSystemVlr

from seminspect.core.errors import FileFormatError
from seminspect.mapping.formats.las import read_las, wkt_linear_unit
from seminspect.mapping.formats.pointfiles import load_point_file

OFFSETS = np.array([1_312_000.0, 850_000.0, 400.0])  # survey feet, as Autzen's header
SCALES = np.array([0.01, 0.01, 0.01])
FEET_WKT = (
    'PROJCS["test",GEOGCS["g",DATUM["d",SPHEROID["s",6378137,298.257]],'
    'UNIT["degree",0.0174532925199433]],PROJECTION["Lambert_Conformal_Conic_2SP"],'
    'UNIT["US survey foot",0.3048006096012192]]'
)


def _points(rng: np.random.Generator, n: int = 500) -> np.ndarray:
    local = rng.uniform([0, 0, 0], [300, 200, 30], (n, 3))
    return np.round(OFFSETS + local, 2)  # on the header's 0.01 grid


def _geo_keys(unit_code: int) -> GeoKeyDirectoryVlr:
    vlr = GeoKeyDirectoryVlr()
    header = GeoKeyEntryStruct(1, 1, 0, 2)  # key directory version 1.1.0, two keys
    model = GeoKeyEntryStruct(1024, 0, 1, 1)  # GTModelTypeGeoKey: projected
    unit = GeoKeyEntryStruct(3076, 0, 1, unit_code)  # ProjLinearUnitsGeoKey
    vlr.geo_keys_header, vlr.geo_keys = header, [model, unit]
    return vlr


def _write(path, points, classes, vlr=None, *, version="1.2", point_format=3) -> None:
    header = laspy.LasHeader(point_format=point_format, version=version)
    header.offsets, header.scales = OFFSETS, SCALES
    if vlr is not None:
        header.vlrs.append(vlr)
    las = laspy.LasData(header)
    las.x, las.y, las.z = points[:, 0], points[:, 1], points[:, 2]
    las.classification = classes
    las.write(path)


@pytest.mark.parametrize("suffix", [".las", ".laz"])
def test_scaled_coordinates_classes_and_feet_from_the_geokeys(tmp_path, suffix) -> None:
    rng = np.random.default_rng(0)
    points = _points(rng)
    classes = rng.choice([1, 2, 6], len(points)).astype(np.uint8)
    path = tmp_path / f"site{suffix}"
    _write(path, points, classes, _geo_keys(9002))
    data = load_point_file(path)
    assert data.points.dtype == np.float64
    np.testing.assert_allclose(data.points, points, atol=1e-6)
    assert np.array_equal(data.classification, classes)
    assert data.labels is None and data.embeddings is None  # classes are truth, not labels
    assert (data.unit, data.vertical_unit) == ("ft", "ft")
    assert data.unit_source == "GeoTIFF key 3076"


def test_us_survey_feet_from_a_wkt_record(tmp_path) -> None:
    rng = np.random.default_rng(1)
    path = tmp_path / "wkt.las"
    vlr = WktCoordinateSystemVlr(FEET_WKT)
    _write(path, _points(rng), np.full(500, 2, np.uint8), vlr, version="1.4", point_format=6)
    data = load_point_file(path)
    assert (data.unit, data.unit_source) == ("us-ft", "WKT")


def test_a_header_without_units_says_none(tmp_path) -> None:
    path = tmp_path / "plain.las"
    _write(path, _points(np.random.default_rng(2)), np.ones(500, np.uint8))
    assert load_point_file(path).unit is None


def test_wkt_units_by_their_factor() -> None:
    assert wkt_linear_unit(FEET_WKT) == "us-ft"
    assert wkt_linear_unit('PROJCS["x",UNIT["foot",0.3048,AUTHORITY["EPSG","9002"]]]') == "ft"
    assert wkt_linear_unit('PROJCRS["x",LENGTHUNIT["metre",1]]') == "m"
    assert wkt_linear_unit('GEOGCS["x",UNIT["degree",0.0174532925199433]]') is None


def test_broken_files_are_one_line_naming_the_file(tmp_path) -> None:
    broken = tmp_path / "broken.las"
    broken.write_bytes(b"LASF" + bytes(50))
    with pytest.raises(FileFormatError, match=r"broken\.las: not a readable LAS file"):
        read_las(broken)
    with pytest.raises(FileFormatError, match=r"missing\.laz: no such file"):
        load_point_file(tmp_path / "missing.laz")


def test_laz_without_a_backend_names_the_extra(tmp_path, monkeypatch) -> None:
    path = tmp_path / "site.laz"
    _write(path, _points(np.random.default_rng(3)), np.ones(500, np.uint8))

    def no_backend(*_args, **_kwargs):
        raise laspy.errors.LazError("No LazBackend selected, cannot decompress data")

    monkeypatch.setattr(laspy, "read", no_backend)
    with pytest.raises(FileFormatError, match=r"site.laz: .*pip install 'seminspect\[laz\]'"):
        load_point_file(path)


def test_autzen_declares_international_feet(shared_data) -> None:
    data = load_point_file(shared_data / "aerial_lidar_las" / "autzen_trim.laz")
    assert (data.unit, data.points.shape) == ("ft", (110_000, 3))
    assert np.bincount(data.classification).tolist()[1:3] == [83_893, 26_107]
