"""``seminspect plan``: paths on OctoMaps written here with pyoctomap, and on Freiburg's."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cli_runner import run
from seminspect.core.io import read_versioned_json

RES = 0.2


def write_rooms_bt(path: Path, door: bool) -> Path:
    """Two rooms x 0..4 and 4..8 m (y 0..3, z 0..2.4), a wall at x = 4 with a door or not,
    as an OctoMap: walls occupied, the rooms free, nothing else known."""
    pyoctomap = pytest.importorskip("pyoctomap")
    tree = pyoctomap.OcTree(RES)
    nx, ny, nz = 40, 15, 12
    for i, j, k in np.ndindex(nx, ny, nz):
        shell = i in (0, nx - 1) or j in (0, ny - 1) or k in (0, nz - 1)
        wall = i == 20 and not (door and 5 <= j < 10 and 1 <= k < 10)
        centre = (np.array([i, j, k]) + 0.5) * RES
        tree.updateNode(centre, bool(shell or wall))
    assert tree.writeBinary(str(path))
    return path


def test_rough_ends_are_snapped_and_the_path_written(capsys, tmp_path: Path) -> None:
    bt = write_rooms_bt(tmp_path / "rooms.bt", door=True)
    out_json, out_csv = tmp_path / "path.json", tmp_path / "path.csv"
    code, out, err = run(
        capsys, "plan", str(bt), "--start", "0.05,1.5,1.2", "--goal", "7.9,1.5,1.2",
        "--out", str(out_json), "--picture", str(tmp_path / "path.png"),
    )  # fmt: skip
    assert code == 0, err
    assert "start (" in out and "moved 0." in out  # out of the wall, by how much
    assert "path: " in out and " m, " in out
    document = read_versioned_json(out_json, "seminspect.map-path", [1])
    waypoints = np.array(document["waypoints"])
    assert np.allclose(waypoints[0], document["start"]["snapped"])
    assert document["start"]["moved_m"] > 0.3
    assert waypoints[:, 0].max() > 7.0  # through the door into the second room
    assert (tmp_path / "path.png").stat().st_size > 0
    code, _, err = run(capsys, "plan", str(bt), "--out", str(out_csv))
    assert code == 0, err
    assert out_csv.read_text().startswith("x,y,z\n")


def test_ends_cut_off_from_each_other_give_one_clear_line(capsys, tmp_path: Path) -> None:
    bt = write_rooms_bt(tmp_path / "walled.bt", door=False)
    code, _, err = run(
        capsys, "plan", str(bt), "--start", "1,1.5,1.2", "--goal", "7,1.5,1.2"
    )  # fmt: skip
    assert code == 1
    assert "different free components" in err and "Traceback" not in err
    assert "comes nearest the goal" in err


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--start", "1,2"], "--start takes x,y,z"),
        (["--start", "1,1.5,1.2"], "both --start and --goal"),
        (["--out", "path.txt"], "use one of .csv, .json"),
    ],
)
def test_bad_options_are_one_line(capsys, tmp_path: Path, args, message) -> None:
    bt = tmp_path / "absent.bt"
    if "--out" in args:
        args = ["--out", str(tmp_path / "path.txt")]
    else:
        bt = write_rooms_bt(tmp_path / "rooms.bt", door=True)
    code, _, err = run(capsys, "plan", str(bt), *args)
    assert code == 1
    assert message in err and "Traceback" not in err


def test_a_plan_along_the_freiburg_corridor_from_rough_points(capsys, shared_data) -> None:
    pytest.importorskip("pyoctomap")
    bt = shared_data / "octomap" / "geb079.bt"
    code, out, err = run(
        capsys, "plan", str(bt), "--start=-6,0,1", "--goal=28,0,1", "--resolution", "0.1"
    )  # fmt: skip
    assert code == 0, err
    length = float(out.split("path: ")[1].split(" m")[0])
    assert 33.0 < length < 40.0  # the corridor is straight: close to the 34 m between the ends
