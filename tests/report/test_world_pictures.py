import matplotlib.pyplot as plt
import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.report.worlds import class_colour, save_world_picture, world_figure
from seminspect.worlds import generate_world


@pytest.mark.parametrize("view", ["top", "3d", "both"])
def test_pictures_are_written_as_png(tmp_path, view) -> None:
    world = generate_world("room", "4", seed=1)
    path = save_world_picture(world, tmp_path / f"room-{view}.png", view)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_top_view_names_every_object() -> None:
    world = generate_world("campus", "medium", seed=0)
    fig = world_figure(world, "top")
    texts = {t.get_text() for t in fig.axes[0].texts}
    plt.close(fig)
    assert {i.name for i in world.instances.values()} <= texts


def test_colours_and_bad_views() -> None:
    assert class_colour("car") != class_colour("truck")
    assert class_colour("dragon") == class_colour("dragon")  # stable for unknown classes
    with pytest.raises(InvalidInputError, match="view"):
        world_figure(generate_world("room", "0"), "side")  # type: ignore[arg-type]


def test_top_view_draws_the_drive_path() -> None:
    world = generate_world("outdoor", "small", seed=0)
    fig = world_figure(world, "top")
    (line,) = [ln for ln in fig.axes[0].lines if ln.get_label() == "drive path"]
    plt.close(fig)
    assert line.get_xydata().tolist() == world.metadata["drive_path"]
    assert len({class_colour(c) for c in ("sidewalk", "grass", "asphalt", "tree")}) == 4
