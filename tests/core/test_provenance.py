import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from seminspect import __version__
from seminspect.core.provenance import (
    code_differences,
    code_version,
    git_revision,
    numeric_fingerprint,
    numeric_platform,
    platform_difference,
    platform_label,
    source_hash,
)


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
    assert set(platform) == {
        "machine", "cpu_vendor", "cpu_model", "simd", "blas_kernels", "fingerprint",
    }  # fmt: skip
    assert platform["machine"]
    # numpy is installed, so its BLAS is found and named.
    assert platform["blas_kernels"]
    assert re.fullmatch(r"[0-9a-f]{16}", platform["fingerprint"])
    assert numeric_fingerprint() == platform["fingerprint"]  # the same paths, the same hash


def _child_platform(**environment: str) -> dict[str, str]:
    """``numeric_platform()`` of a fresh interpreter with ``environment`` added."""
    code = "import json; from seminspect.core.provenance import numeric_platform as p; "
    code += "print(json.dumps(p()))"
    done = subprocess.run(
        [sys.executable, "-c", code],
        env={**os.environ, **environment},
        capture_output=True,
        text=True,
        check=True,
        timeout=120,
    )
    return json.loads(done.stdout)


def test_the_fingerprint_tells_other_blas_kernels_apart() -> None:
    # OpenBLAS's kernels can be forced, which gives this machine another floating-point path
    # with every named field but one unchanged: the fingerprint must see it too.
    here = numeric_platform()
    other_kernels = "Nehalem" if here["blas_kernels"] == "Sandybridge" else "Sandybridge"
    there = _child_platform(OPENBLAS_CORETYPE=other_kernels)
    if there["blas_kernels"] == here["blas_kernels"]:
        pytest.skip("this numpy's OpenBLAS cannot be given other kernels")
    assert there["fingerprint"] != here["fingerprint"]
    assert _child_platform() == here  # and a second process on the same paths agrees


def test_a_platform_difference_is_named_field_by_field() -> None:
    was = {"machine": "x86_64", "simd": "avx2", "blas_kernels": "Zen"}
    now = {"machine": "x86_64", "simd": "avx512f", "blas_kernels": "Zen", "fingerprint": "ab12"}
    assert platform_difference(was, now) == "simd avx2 -> avx512f, fingerprint unrecorded -> ab12"
    assert platform_label(now) == "x86_64 avx512f Zen #ab12"


def test_a_run_from_another_machine_differs_unless_it_did_not_record_one() -> None:
    record = code_version()
    elsewhere = {**record, "platform": {**record["platform"], "cpu_vendor": "OtherVendor"}}
    (difference,) = code_differences(elsewhere, record)
    assert difference == f"machine cpu_vendor OtherVendor -> {record['platform']['cpu_vendor']}"
    # A run recorded before the fingerprint was cannot vouch for this machine's paths.
    older = {**record, "platform": {**record["platform"]}}
    del older["platform"]["fingerprint"]
    assert code_differences(older, record) == [
        f"machine fingerprint unrecorded -> {record['platform']['fingerprint']}"
    ]
    unrecorded = {key: value for key, value in record.items() if key != "platform"}
    assert code_differences(unrecorded, record) == []


def test_the_blas_named_is_numpys_whatever_else_is_loaded() -> None:
    import cv2  # noqa: F401 - OpenCV loads an OpenBLAS of its own
    from threadpoolctl import threadpool_info

    (numpy_blas,) = [
        lib for lib in threadpool_info() if "numpy" in Path(lib["filepath"]).parent.name
    ]
    assert numeric_platform.__wrapped__()["blas_kernels"] == numpy_blas["architecture"]
