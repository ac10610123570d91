"""The entry point on hostile input: one literal line, the right exit code, nothing left behind."""

import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from cli_runner import run
from full_disk import fill_disk
from seminspect.cli import _common as cli_common
from seminspect.cli.graph import example_graph_path
from seminspect.mapping.semantic_cloud import CLOUD_FORMAT
from seminspect.missions.xflie.layout import XFLIE_LAYOUT
from seminspect.runs.directory import clear_previous_run
from seminspect.runs.status import read_run_status


def _graph_with_version(tmp_path: Path, version: object) -> str:
    document = json.loads(example_graph_path().read_text())
    document["version"] = version
    path = tmp_path / f"graph-{version}.json"
    path.write_text(json.dumps(document))
    return str(path)


def _cloud_with_version(tmp_path: Path, version: object) -> str:
    path = tmp_path / "cloud.npz"
    arrays = {"format": np.array(CLOUD_FORMAT), "version": np.array(version)}
    np.savez(path, points=np.zeros((3, 3)), **arrays)
    return str(path)


def _folder(tmp_path: Path, name: str) -> str:
    (tmp_path / name).mkdir()
    return str(tmp_path / name)


def _existing_file(tmp_path: Path) -> str:
    path = tmp_path / "taken"
    path.write_text("not a directory")
    return str(path)


# (arguments built from tmp_path, a phrase the one error line must hold)
HOSTILE = {
    "graph export --out a directory": (
        lambda t: ["graph", "export", "example", "--out", str(t)],
        "is a directory",
    ),
    "graph show --out a directory": (
        lambda t: ["graph", "show", "example", "--out", str(t)],
        "is a directory",
    ),
    "graph show --out x.xyz": (
        lambda t: ["graph", "show", "example", "--out", str(t / "x.xyz")],
        "use one of .png, .svg, .pdf",
    ),
    "graph show --out under a file": (
        lambda t: ["graph", "show", "example", "--out", _existing_file(t) + "/g.png"],
        "is not a directory",
    ),
    "world show --out a directory": (
        lambda t: ["world", "show", "campus", "--out", str(t)],
        "is a directory",
    ),
    "world export --out an existing file": (
        lambda t: ["world", "export", "campus", "--out", _existing_file(t)],
        "exists and is not a directory",
    ),
    "mission --out an existing file": (
        lambda t: ["mission", "--world", "subterranean", "--out", _existing_file(t)],
        "exists and is not a directory",
    ),
    "terrain graph --out an existing file": (
        lambda t: ["terrain", "graph", "c.ply", "--out", _existing_file(t)],
        "exists and is not a directory",
    ),
    "terrain graph --radius -1": (
        lambda t: ["terrain", "graph", "c.ply", "--out", str(t / "o"), "--radius", "-1"],
        "--radius must be a positive number",
    ),
    "a directory as a cloud": (
        lambda t: ["terrain", "graph", str(t), "--out", str(t / "o"), "--encoder", "hashing-test"],
        "is a directory",
    ),
    "a directory named like a cloud": (
        lambda t: ["terrain", "graph", _folder(t, "scans.npz"), "--out", str(t / "o"),
                   "--encoder", "hashing-test"],
        "is a directory",
    ),
    "a cloud with a text version": (
        lambda t: ["terrain", "graph", _cloud_with_version(t, "one"), "--out", str(t / "o"),
                   "--encoder", "hashing-test"],
        "semantic cloud version 'one' is not supported",
    ),
    "a cloud with a float version": (
        lambda t: ["terrain", "graph", _cloud_with_version(t, 1.0), "--out", str(t / "o"),
                   "--encoder", "hashing-test"],
        "semantic cloud version 1.0 is not supported",
    ),
    "a graph with version true": (
        lambda t: ["graph", "info", _graph_with_version(t, True)],
        "version True is not supported",
    ),
    "a graph with version 1.0": (
        lambda t: ["graph", "info", _graph_with_version(t, 1.0)],
        "version 1.0 is not supported",
    ),
    "mission --budget inf": (
        lambda t: ["mission", "--world", "subterranean", "--budget", "inf", "--out", str(t / "r")],
        "time_budget_s",
    ),
    "mission --budget nan": (
        lambda t: ["mission", "--world", "subterranean", "--budget", "nan", "--out", str(t / "r")],
        "--budget",
    ),
    "mission with an unknown scenario": (
        lambda t: ["mission", "--world", "campus", "-s", "huge", "--out", str(t / "r")],
        "unknown campus scenario 'huge'",
    ),
    "mission with a mesh path as --world": (
        lambda t: ["mission", "--world", str(t / "site.obj"), "--out", str(t / "r")],
        "no such world file",
    ),
}  # fmt: skip


@pytest.mark.parametrize("case", sorted(HOSTILE))
def test_hostile_input_gets_one_clear_line(capsys, tmp_path, fake_encoder, case) -> None:
    build, phrase = HOSTILE[case]
    args = build(tmp_path)  # makes the hostile input files
    inputs = set(tmp_path.iterdir())
    code, _, err = run(capsys, *args)
    assert code in (1, 2), err
    assert phrase in err and "internal error" not in err and "Traceback" not in err
    assert err.strip().count("\n") == 0, err
    assert set(tmp_path.iterdir()) == inputs  # no fake run directory or output left behind


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only directories")
@pytest.mark.parametrize(
    "args",
    [["mission", "--world", "subterranean"], ["world", "export", "campus"]],
)
def test_an_out_in_a_read_only_directory_is_refused_before_work(capsys, tmp_path, args) -> None:
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o500)
    code, _, err = run(capsys, *args, "--out", str(locked / "run"))
    assert code == 1 and "not writable" in err and str(locked) in err


def test_an_unwritable_folder_is_named_before_work(capsys, tmp_path, monkeypatch) -> None:
    monkeypatch.setattr(cli_common.os, "access", lambda path, mode: False)  # as for non-root
    for args in (["world", "export", "campus"], ["graph", "show", "example"]):
        code, _, err = run(capsys, *args, "--out", str(tmp_path / "new" / "out.png"))
        assert code == 1 and f"{tmp_path} is not writable" in err, err


@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux /proc")
def test_a_file_the_system_will_not_write_is_one_line_naming_it(capsys) -> None:
    code, _, err = run(capsys, "graph", "export", "example", "--out", "/proc/seminspect.json")
    assert code == 1 and err.startswith("error: /proc/seminspect.json: ") and err.count("\n") == 1


@pytest.mark.parametrize("text", ["Visit [/b]car-1", "Visit [blink]car-1[/blink]"])
def test_user_text_is_printed_as_typed(capsys, text) -> None:
    code, _, err = run(capsys, "graph", "query", "example", text)
    assert code == 1 and text.split()[1] in err and "Traceback" not in err


def test_a_path_with_markup_is_printed_as_typed(capsys, tmp_path) -> None:
    out = tmp_path / "[/b]graph.graphml"
    code, text, err = run(capsys, "graph", "export", "example", "--out", str(out))
    assert code == 0 and out.exists() and f"wrote {out}" in text.replace("\n", ""), err


def test_nan_coordinates_are_named_in_the_error(capsys) -> None:
    code, _, err = run(
        capsys, "graph", "query", "example", "Visit car-1", "--from", "nan", "nan", "nan"
    )
    assert code == 1 and "nan" in err.lower().split("got", 1)[-1]


def test_a_user_world_folder_works_where_a_name_does(capsys, tmp_path) -> None:
    code, _, _ = run(capsys, "world", "export", "subterranean", "--out", str(tmp_path / "[/b]site"))
    assert code == 0
    code, text, err = run(
        capsys, "world", "show", str(tmp_path / "[/b]site"), "--out", str(tmp_path / "site.png")
    )
    assert code == 0, err
    assert (tmp_path / "site.png").read_bytes()[:4] == b"\x89PNG" and "car-1" in text
    code, _, err = run(capsys, "world", "show", str(tmp_path / "[/b]site"), "--scenario", "small")
    assert code == 1 and "has no scenarios" in err
    code, text, err = run(
        capsys, "mission", "--world", str(tmp_path / "[/b]site"), "--budget", "5", "--no-pictures",
        "--out", str(tmp_path / "run"),
    )  # fmt: skip
    assert code == 0, err
    config = json.loads((tmp_path / "run" / "config.json").read_text())["config"]
    assert config["world"] == str((tmp_path / "[/b]site").resolve()) and config["scenario"] is None


def test_a_full_disk_fails_the_mission_in_one_line_naming_the_file(capsys, tmp_path, monkeypatch):
    out = tmp_path / "run"
    args = ("mission", "-w", "subterranean", "--budget", "5", "--no-pictures", "-o", str(out))
    fill_disk(monkeypatch, "graph.json")
    code, _, err = run(capsys, *args)
    assert code == 1 and len(err.strip().splitlines()) == 1, err
    assert "no space left on device, writing graph.json" in err and str(out) in err
    status = read_run_status(out)
    assert status.state == "failed" and "writing graph.json" in status.reason
    monkeypatch.undo()
    clear_previous_run(out, XFLIE_LAYOUT)  # what 'mission --out' does first: nothing refused


def test_an_end_of_file_is_a_bug_not_a_ctrl_c(capsys, monkeypatch) -> None:
    def truncated(*args, **kwargs):
        raise EOFError("Ran out of input")

    monkeypatch.setattr("seminspect.cli.graph.example_graph_path", truncated)
    code, _, err = run(capsys, "graph", "show", "example")
    assert code == 3 and err.startswith("internal error: EOFError: Ran out of input"), err


@pytest.fixture
def small_disk(tmp_path):
    """``small_disk(size)``: a folder on a tmpfs of ``size`` (root only; skipped elsewhere)."""
    mounted: list[Path] = []

    def mount(size: str) -> Path:
        folder = tmp_path / f"disk-{size}"
        folder.mkdir()
        if os.geteuid() != 0:
            pytest.skip("mounting a small tmpfs needs root")
        command = ["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(folder)]
        if subprocess.run(command, check=False, capture_output=True).returncode != 0:
            pytest.skip("mount cannot mount a tmpfs here")
        mounted.append(folder)
        return folder

    yield mount
    for folder in mounted:
        subprocess.run(["umount", str(folder)], check=True)


@pytest.mark.parametrize("size", ["4k", "12k"])
def test_a_mission_on_a_small_disk_leaves_a_truthful_directory(capsys, small_disk, size) -> None:
    out = small_disk(size) / "run"
    args = ("mission", "-w", "subterranean", "--budget", "5", "--no-pictures", "-o", str(out))
    code, _, err = run(capsys, *args)
    assert code == 1 and len(err.strip().splitlines()) == 1, err
    assert "no space left on device, writing " in err and str(out) in err
    if (out / "status.json").exists():
        status = read_run_status(out)
        assert status.state == "failed" and "no space left on device, writing " in status.reason
    else:  # not even the status fitted: the line says so
        assert "could not record how the run ended" in err
    clear_previous_run(out, XFLIE_LAYOUT)  # what 'mission --out' does first: nothing refused
