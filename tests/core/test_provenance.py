from pathlib import Path

from seminspect import __version__
from seminspect.core.provenance import code_differences, code_version, git_revision, source_hash


def test_the_source_hash_follows_every_python_file(tmp_path: Path) -> None:
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "a.py").write_text("x = 1\n")
    (tmp_path / "pkg" / "notes.txt").write_text("ignored")
    before = source_hash(tmp_path)
    (tmp_path / "pkg" / "notes.txt").write_text("still ignored")
    assert source_hash.__wrapped__(tmp_path) == before
    (tmp_path / "pkg" / "a.py").write_text("x = 2\n")
    assert source_hash.__wrapped__(tmp_path) != before


def test_a_folder_outside_git_has_no_revision(tmp_path: Path) -> None:
    assert git_revision(tmp_path) is None


def test_the_record_names_the_package_and_what_changed() -> None:
    record = code_version()
    assert record["seminspect"] == __version__ and record["dependencies"]["scipy"]
    assert code_differences(record, record) == []
    older = {**record, "dependencies": {**record["dependencies"], "scipy": "1.0"}}
    assert code_differences(older, record) == [f"scipy 1.0 -> {record['dependencies']['scipy']}"]


def test_the_record_names_the_machines_floating_point_paths() -> None:
    platform = code_version()["platform"]
    assert set(platform) == {"machine", "cpu_vendor", "simd", "blas_kernels"}
    assert platform["machine"]
    # numpy is installed, so its BLAS is found and named.
    assert platform["blas_kernels"]


def test_a_run_from_another_machine_differs_unless_it_did_not_record_one() -> None:
    record = code_version()
    elsewhere = {**record, "platform": {**record["platform"], "cpu_vendor": "OtherVendor"}}
    (difference,) = code_differences(elsewhere, record)
    assert difference.startswith("machine ") and "OtherVendor" in difference
    unrecorded = {key: value for key, value in record.items() if key != "platform"}
    assert code_differences(unrecorded, record) == []


def test_the_blas_named_is_numpys_whatever_else_is_loaded() -> None:
    import cv2  # noqa: F401 - OpenCV loads an OpenBLAS of its own
    from threadpoolctl import threadpool_info

    from seminspect.core.provenance import numeric_platform

    (numpy_blas,) = [
        lib for lib in threadpool_info() if "numpy" in Path(lib["filepath"]).parent.name
    ]
    assert numeric_platform.__wrapped__()["blas_kernels"] == numpy_blas["architecture"]
