import json

import numpy as np
import pytest

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.missions.routine.tasks import default_tasks, load_tasks
from seminspect.worlds.routine_sites import SitePair, mine_drift_site

FACE = [[20.0, 1.3, 0.8], [20.0, 3.7, 0.8], [20.0, 3.7, 2.4], [20.0, 1.3, 2.4]]


def test_yaml_and_json_task_files_give_the_same_regions(tmp_path):
    (tmp_path / "t.yaml").write_text(f"regions:\n  - name: face\n    vertices: {FACE}\n")
    (tmp_path / "t.json").write_text(json.dumps({"regions": [{"name": "face", "vertices": FACE}]}))
    from_yaml, from_json = load_tasks(tmp_path / "t.yaml"), load_tasks(tmp_path / "t.json")
    assert [r.name for r in from_yaml] == ["face"]
    np.testing.assert_array_equal(from_yaml[0].vertices, from_json[0].vertices)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("regions: [}", "YAML"),
        ("regions: []", "regions"),
        ("regions:\n  - name: a\n    vertices: [[0, 0, 0], [0, 1, 0]]\n", ">= 3 vertices"),
        (
            "regions:\n  - name: a\n    vertices: [[0, 0, 0], [0, 1, 0], [0, 1, .nan]]\n",
            "finite|NaN",
        ),
        (
            "regions:\n  - name: a\n    vertices: [[0, 0, 0], [0, 1, 0], [0, 1, 1], [0.4, 0, 1]]\n",
            "not planar",
        ),
        ("regions:\n  - name: a\n    vertices: [[0, 0, 0], [1, 0, 0], [1, 1, 0]]\n", "wall-like"),
        ("regions:\n  - name: a\n    verts: []\n", "vertices"),
    ],
)
def test_broken_task_files_name_the_file_and_the_problem(tmp_path, text, message):
    path = tmp_path / "tasks.yaml"
    path.write_text(text)
    with pytest.raises(FileFormatError, match=message) as caught:
        load_tasks(path)
    assert "tasks.yaml" in str(caught.value)


def test_duplicate_names_and_wrong_suffix_are_refused(tmp_path):
    path = tmp_path / "t.yaml"
    path.write_text(
        f"regions:\n  - name: a\n    vertices: {FACE}\n  - name: a\n    vertices: {FACE}\n"
    )
    with pytest.raises(FileFormatError, match="unique"):
        load_tasks(path)
    with pytest.raises(FileFormatError, match="yaml"):
        load_tasks(tmp_path / "t.txt")
    with pytest.raises(FileFormatError, match="no such file"):
        load_tasks(tmp_path / "missing.yaml")


def test_every_scenario_has_default_tasks_a_user_site_none():
    for scenario in ("nominal", "receding", "advancing", "obstructed"):
        site = mine_drift_site(scenario, 0, 12.0)
        assert len(default_tasks(site)) == len(site.tasks) >= 1
    bare = SitePair("user", 0, site.historical, site.current, {"kind": "user"})
    with pytest.raises(InvalidInputError, match="task file"):
        default_tasks(bare)


def task_file(tmp_path, vertices, name="face"):
    path = tmp_path / "tasks.yaml"
    path.write_text(f"regions:\n  - name: {name}\n    vertices: {vertices}\n")
    return path


def test_a_self_crossing_region_is_refused_with_the_reason(tmp_path):
    bowtie = [[20.0, 1.3, 0.8], [20.0, 3.7, 2.4], [20.0, 3.7, 0.8], [20.0, 1.3, 2.4]]
    path = task_file(tmp_path, bowtie, "bowtie")
    with pytest.raises(FileFormatError) as caught:
        load_tasks(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: region 'bowtie' is not a simple polygon (")
    assert "Self-intersection" in message and "in order around its outline" in message


def test_a_region_away_from_the_site_is_refused_naming_it(tmp_path):
    site = mine_drift_site("nominal", 0, 20.0)
    far = np.add(FACE, [0.0, 1000.0, 0.0]).tolist()
    path = task_file(tmp_path, far, "far-face")
    assert load_tasks(path)[0].name == "far-face"  # without the site nothing says where it is
    with pytest.raises(FileFormatError) as caught:
        load_tasks(path, site)
    message = str(caught.value)
    assert message.startswith(f"{path}: region 'far-face' spans x 20.0..20.0 y 1001.3..1003.7")
    assert "outside the site (x 0.0..21.0 y 0.0..5.0 z 0.0..4.5)" in message


@pytest.mark.parametrize("scenario", ["nominal", "receding", "advancing", "obstructed"])
def test_the_default_regions_lie_on_their_site(tmp_path, scenario):
    site = mine_drift_site(scenario, 0, 12.0)
    regions = default_tasks(site)
    lines = "".join(f"  - name: {r.name}\n    vertices: {r.vertices.tolist()}\n" for r in regions)
    (tmp_path / "t.yaml").write_text("regions:\n" + lines)
    assert [r.name for r in load_tasks(tmp_path / "t.yaml", site)] == [r.name for r in regions]
