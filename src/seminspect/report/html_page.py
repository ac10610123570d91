"""The machinery of ``report.html`` that every run kind shares: the page, its tables, its traces.

A page is plotly.js once (inline, so it opens from disk with no network), its figures, titled
HTML sections and the small JPEG thumbnails it embeds. The first figure of a page with a hover
panel is its scene (``figure-scene``): hovering a point there shows the point's text and, where
it refers to one, its image beside the view. Every trace a reader may want to count carries
``meta = {"layer": name, "nodes": count}``.
"""

from __future__ import annotations

import base64
import html
import json
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import plotly.graph_objects as go
from numpy.typing import NDArray

from seminspect.core.errors import FileFormatError
from seminspect.core.io import atomic_write_text

REPORT_FILE = "report.html"
#: Thumbnails are this wide (pixels) and this JPEG quality: enough to recognise a view.
THUMBNAIL_WIDTH = 160
THUMBNAIL_QUALITY = 70
#: A run's own pictures (its PNGs) are shown this wide; a click opens the full picture.
PICTURE_WIDTH = 480

HOVER_HINT = "Hover a node to see its name, label, score and image."


@dataclass(frozen=True)
class Section:
    """One titled block of the page (already HTML)."""

    title: str
    body: str


def document_format(path: Path) -> str | None:
    """The ``format`` tag of a JSON document (None when it has none)."""
    try:
        document = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise FileFormatError(f"{path}: not readable JSON ({exc})") from None
    return document.get("format") if isinstance(document, dict) else None


def node_trace(
    xyz: NDArray, name: str, colour: str | list[str], hover: list[str], images: list[str]
):
    """Nodes of one layer as one 3D trace (one legend entry), counted in ``meta``."""
    return go.Scatter3d(
        x=xyz[:, 0], y=xyz[:, 1], z=xyz[:, 2], mode="markers", name=f"{name} ({len(xyz)})",
        marker={"size": 5, "color": colour, "line": {"width": 0}}, hovertext=hover,
        hoverinfo="text", customdata=images, meta={"layer": name, "nodes": len(xyz)},
    )  # fmt: skip


def segments_trace(pairs: Sequence[tuple[NDArray, NDArray]], name: str, colour: str, dash: str):
    """Many line segments as one trace, separated by gaps (one legend entry, fast to draw)."""
    coords: list[list[float | None]] = [[], [], []]
    for a, b in pairs:
        for axis in range(3):
            coords[axis] += [float(a[axis]), float(b[axis]), None]
    return go.Scatter3d(
        x=coords[0], y=coords[1], z=coords[2], mode="lines", name=f"{name} ({len(pairs)})",
        line={"color": colour, "width": 2, "dash": dash}, hoverinfo="skip",
    )  # fmt: skip


def scene_layout(figure, title: str) -> None:
    """A tall 3D view with true proportions."""
    figure.update_layout(
        title=title, height=760, margin={"l": 0, "r": 0, "t": 40, "b": 0},
        scene={"aspectmode": "data", "xaxis_title": "x [m]", "yaxis_title": "y [m]"},
        legend={"itemsizing": "constant"},
    )  # fmt: skip


def key_value_table(values: Mapping[str, Any]) -> str:
    """An HTML table of a (possibly nested) mapping; nested mappings become sub-tables."""
    rows = []
    for key, value in values.items():
        if isinstance(value, Mapping):
            cell = key_value_table(value)
        elif isinstance(value, float):
            cell = f"{value:.3f}"
        elif isinstance(value, list | tuple):
            cell = html.escape(", ".join(_short(v) for v in value))
        else:
            cell = html.escape(_short(value))
        rows.append(f"<tr><th>{html.escape(str(key))}</th><td>{cell}</td></tr>")
    return "<table>" + "".join(rows) + "</table>"


def rows_table(headers: Sequence[str], rows: Iterable[Sequence[Any]]) -> str:
    """An HTML table with a header row; floats to three decimals, None as a dash."""
    head = "".join(f"<th>{html.escape(h)}</th>" for h in headers)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(_short(v))}</td>" for v in row) + "</tr>"
        for row in rows
    )
    return f"<table><tr>{head}</tr>{body}</table>"


def _short(value: Any) -> str:
    if value is None:
        return "-"
    return f"{value:.3f}" if isinstance(value, float) else str(value)


def _jpeg_uri(path: Path, width: int) -> str | None:
    image = cv2.imread(str(path), cv2.IMREAD_COLOR)
    if image is None:
        return None
    height = max(1, round(image.shape[0] * width / image.shape[1]))
    small = cv2.resize(image, (width, height), interpolation=cv2.INTER_AREA)
    ok, encoded = cv2.imencode(".jpg", small, [cv2.IMWRITE_JPEG_QUALITY, THUMBNAIL_QUALITY])
    return "data:image/jpeg;base64," + base64.b64encode(encoded.tobytes()).decode() if ok else None


def thumbnails(root: Path, images: Iterable[str]) -> dict[str, str]:
    """Each referenced image as a small JPEG data URI (missing or unreadable ones are left out)."""
    found = {}
    for relative in sorted(images):
        uri = _jpeg_uri(root / relative, THUMBNAIL_WIDTH)
        if uri is not None:
            found[relative] = uri
    return found


def pictures_section(root: Path, names: Iterable[str], title: str = "Pictures") -> Section | None:
    """The run's PNGs that exist, embedded small, each a link to the full picture beside the
    page; None when there are none."""
    cells = []
    for name in names:
        uri = _jpeg_uri(root / name, PICTURE_WIDTH) if (root / name).is_file() else None
        if uri is None:
            continue
        label = html.escape(name)
        cells.append(
            f'<figure><a href="{label}"><img alt="{label}" src="{uri}"></a>'
            f"<figcaption>{label}</figcaption></figure>"
        )
    if not cells:
        return None
    return Section(title, '<div class="pictures">' + "".join(cells) + "</div>")


#: Shows the hovered point's text and thumbnail beside the scene.
_HOVER_SCRIPT = """
const thumbnails = JSON.parse(document.getElementById('thumbnails').textContent);
const scene = document.getElementById('figure-scene');
const panel = document.getElementById('hover-panel');
scene.on('plotly_hover', (event) => {
  const point = event.points[0];
  const text = Array.isArray(point.data.hovertext) ? point.data.hovertext[point.pointNumber] : '';
  const image = point.customdata ? thumbnails[point.customdata] : undefined;
  panel.innerHTML = (text || '') + (image ? '<br><img alt="view" src="' + image + '">' : '');
});
"""

_STYLE = """
body { font-family: sans-serif; margin: 1em 2em; color: #222; }
table { border-collapse: collapse; margin: 0.3em 0; }
th, td { border: 1px solid #ccc; padding: 2px 8px; text-align: left; vertical-align: top; }
th { background: #f3f3f3; font-weight: normal; }
#scene-row { display: flex; flex-direction: row-reverse; gap: 1em; }
#scene-row > div:not(#hover-panel) { flex: 1; min-width: 0; }
#hover-panel { width: 200px; flex: none; font-size: 0.85em; }
"""
#: Added only to pages that show pictures, so the other pages stay as they were.
_PICTURES_STYLE = """.pictures { display: flex; flex-wrap: wrap; gap: 1em; }
.pictures figure { margin: 0; }
"""


def write_page(
    path: Path,
    title: str,
    figures: Sequence[tuple[str, Any]],
    sections: Sequence[Section],
    thumbnails: Mapping[str, str],
    *,
    hover_hint: str | None = HOVER_HINT,
    trailing: Sequence[Section] = (),
) -> Path:
    """The page: plotly.js once (inline), the first figure (with its hover panel unless
    ``hover_hint`` is None), the sections, the other figures, then ``trailing`` sections."""
    divs = []
    for index, (name, figure) in enumerate(figures):
        divs.append(
            figure.to_html(
                full_html=False, include_plotlyjs=index == 0, div_id=f"figure-{name}",
                config={"displaylogo": False},
            )
        )  # fmt: skip
    first, others = divs[0], divs[1:]
    tables = "".join(f"<h2>{html.escape(s.title)}</h2>{s.body}" for s in sections)
    after = "".join(f"<h2>{html.escape(s.title)}</h2>{s.body}" for s in trailing)
    style = _STYLE + (_PICTURES_STYLE if 'class="pictures"' in tables + after else "")
    if hover_hint is None:
        top, script = f"<div>{first}</div>", ""
    else:
        # the panel comes first and is shown on the right (row-reverse): plotly sizes a figure
        # when it draws it, so a panel parsed after the figure would end up beneath it
        top = (
            f'<div id="scene-row"><div id="hover-panel">{html.escape(hover_hint)}</div>\n'
            f"<div>{first}</div></div>"
        )
        # "</" cannot appear inside a script element; base64 and JSON escapes keep it out
        thumbnail_json = json.dumps(dict(thumbnails)).replace("</", "<\\/")
        script = (
            f'<script type="application/json" id="thumbnails">{thumbnail_json}</script>\n'
            f"<script>{_HOVER_SCRIPT}</script>\n"
        )
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>
<style>{style}</style></head>
<body><h1>{html.escape(title)}</h1>
{top}
{tables}
{"".join(others)}{after}
{script}</body></html>
"""
    return atomic_write_text(path, page)
