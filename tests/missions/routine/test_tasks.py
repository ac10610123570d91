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
