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
