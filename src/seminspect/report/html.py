"""``report.html``: one self-contained page per run directory, drawn from the directory alone.

The page needs no network and no server: plotly.js is embedded inline, and the images a graph
refers to travel as small JPEG thumbnails inside the page (:mod:`~seminspect.report.html_page`).
Each run kind has its own page, and :func:`write_report` tells them apart by what the directory
holds:

* a mission run (``graph.json`` is a 3DLSG): :mod:`~seminspect.report.html_mission`;
* a terrain graph (``graph.json`` is a terrain scene graph): :mod:`~seminspect.report.html_terrain`;
* a routine inspection run (``metrics.json`` or ``tour.json`` tagged as one), a recorded
  ``M_H`` (``routine map``) and a ``--compare`` directory: :mod:`~seminspect.report.html_routine`;
* an ``rl eval`` directory (``evaluation.json``): :mod:`~seminspect.report.html_rl`.

Every layer trace carries ``meta = {"layer": name, "nodes": count}`` so a reader (or a browser
test) can check the figure against the files.
"""

from __future__ import annotations

import os
from pathlib import Path

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.graphs.lsg.io import FORMAT as LSG_FORMAT
from seminspect.graphs.terrain.io import GRAPH_FORMAT as TERRAIN_FORMAT
from seminspect.missions.learning.evaluation import FORMAT as RL_FORMAT
from seminspect.report.html_mission import mission_scene_figure, path_plot, write_mission_report
from seminspect.report.html_page import (
    REPORT_FILE,
    THUMBNAIL_QUALITY,
    THUMBNAIL_WIDTH,
    Section,
    document_format,
    key_value_table,
)
from seminspect.report.html_rl import EVALUATION_FILE, write_rl_report
from seminspect.report.html_routine import (
    is_routine_map,
    is_routine_run,
    routine_runs_below,
    write_routine_comparison_report,
    write_routine_map_report,
    write_routine_report,
)
from seminspect.report.html_terrain import (
    MAX_TERRAIN_POINTS,
    terrain_scene_figure,
    write_terrain_report,
)

__all__ = [
    "MAX_TERRAIN_POINTS",
    "REPORT_FILE",
    "THUMBNAIL_QUALITY",
    "THUMBNAIL_WIDTH",
    "Section",
    "key_value_table",
    "mission_scene_figure",
    "path_plot",
    "run_kind",
    "terrain_scene_figure",
    "write_mission_report",
    "write_report",
    "write_rl_report",
    "write_routine_comparison_report",
    "write_routine_map_report",
    "write_routine_report",
    "write_terrain_report",
]

#: What :func:`run_kind` looks for, in the words of the error when a directory has none of it.
LOOKED_FOR = (
    "no graph.json (mission or terrain graph), routine metrics.json or tour.json, "
    "routine map, evaluation.json (rl eval) or routine runs below it"
)
_WRITERS = {
    "mission": write_mission_report,
    "terrain": write_terrain_report,
    "routine": write_routine_report,
    "routine-map": write_routine_map_report,
    "routine-compare": write_routine_comparison_report,
    "rl-eval": write_rl_report,
}


def run_kind(run_dir: str | os.PathLike[str]) -> str:
    """``mission``, ``terrain``, ``routine``, ``routine-map``, ``routine-compare`` or ``rl-eval``,
    read from the files' format tags; a directory that is none of them is refused in one line."""
    root = Path(run_dir)
    if not root.is_dir():
        raise InvalidInputError(f"{root} is not a directory")
    graph_file = root / "graph.json"
    if graph_file.is_file():
        kind = document_format(graph_file)
        if kind == LSG_FORMAT:
            return "mission"
        if kind == TERRAIN_FORMAT:
            return "terrain"
        raise FileFormatError(
            f"{graph_file}: neither a 3DLSG nor a terrain graph (format {kind!r})"
        )
    if is_routine_run(root):
        return "routine"
    evaluation = root / EVALUATION_FILE
    if evaluation.is_file() and document_format(evaluation) == RL_FORMAT:
        return "rl-eval"
    if is_routine_map(root):
        return "routine-map"
    if routine_runs_below(root):
        return "routine-compare"
    raise InvalidInputError(f"{root} is not a run directory ({LOOKED_FOR})")


def write_report(run_dir: str | os.PathLike[str]) -> Path:
    """Write ``report.html`` for any run directory (:func:`run_kind`); returns its path."""
    return _WRITERS[run_kind(run_dir)](Path(run_dir))
