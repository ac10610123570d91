"""Reports: pictures and tables made from graphs, worlds and run directories."""

from seminspect.report.lsg import draw_layers
from seminspect.report.run_pictures import render_run
from seminspect.report.worlds import save_world_picture, world_figure

__all__ = [
    "draw_layers",
    "render_run",
    "save_world_picture",
    "world_figure",
]
