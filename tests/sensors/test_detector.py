"""The detector seam: the simulator's labels as one Detector, and the platform taking any."""

from __future__ import annotations

import pytest

from seminspect.core.errors import InvalidInputError
from seminspect.core.rng import make_rng
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.sensors import CameraModel, Detection, Frame, TruthDetector, detect, render
from seminspect.sensors.detector import reads_image
from seminspect.sensors.noise import noise_preset
from seminspect.sensors.segmentation import Level, as_level
from seminspect.worlds import WorldBuilder
from seminspect.worlds.shapes import pose_matrix
from seminspect.worlds.vehicles import vehicle_pieces


@pytest.fixture(scope="module")
def scene():
    builder = WorldBuilder("street")
    builder.add_ground((-10, -30), (60, 30))
    builder.add_object(vehicle_pieces("car"), "car", pose_matrix((8.0, -1.0, 0.0), 0.3))
    world = builder.build([(-10, -30, 0), (60, 30, 5)], (0, 0, 0))
    return world, render(world, CameraModel(width=320, height=240), (0, 0, 0.7), quat_from_yaw(0))


def _same(a: list[Detection], b: list[Detection]) -> bool:
    key = [(d.label, d.area_px, d.score, d.bbox, d.instance_id, d.level) for d in a]
    return key == [(d.label, d.area_px, d.score, d.bbox, d.instance_id, d.level) for d in b]


def test_the_truth_detector_is_the_fault_model_on_the_simulators_labels(scene) -> None:
    world, frame = scene
    noise = noise_preset("realistic")
    detector = TruthDetector(world, noise, make_rng(3, "detector"))
    rng = make_rng(3, "detector")  # the same stream, drawn in the same order
    cars = detector.detect(frame, "instance", ["car"])
    assert _same(cars, detect(frame, world, "instance", classes=["car"], noise=noise, rng=rng))
    assert cars and all(d.level == "instance" for d in cars)
    parts = detector.detect(frame, "part", ["hood", "windshield"])
    assert _same(
        parts, detect(frame, world, "part", parts=["hood", "windshield"], noise=noise, rng=rng)
    )
    assert {d.label for d in parts if not d.is_false_positive} <= {"hood", "windshield"}
    assert detector.name == "truth"


def test_a_detection_level_is_instance_or_part() -> None:
    assert as_level("part") == "part"
    with pytest.raises(InvalidInputError, match="'instance' or 'part', got 'pixel'"):
        as_level("pixel")


class _Counting:
    """A detector of our own: the truth one behind a call count, under its own name."""

    name = "counting"

    def __init__(self, inner: TruthDetector) -> None:
        self.inner, self.calls = inner, 0

    def detect(self, frame: Frame, level: Level, labels) -> list[Detection]:
        self.calls += 1
        return self.inner.detect(frame, level, labels)


def test_a_mission_sees_through_the_detector_it_is_given() -> None:
    from seminspect.missions.xflie.build import build_mission
    from seminspect.missions.xflie.config import make_config, resolve

    config = resolve(make_config({"world": "campus", "scenario": "small", "seed": 0}))
    default, world = build_mission(config, None)
    assert isinstance(default.platform.detector, TruthDetector)
    counting = _Counting(TruthDetector(world, noise_preset("ideal"), make_rng(0, "test")))
    mission, _ = build_mission(config, None, world=world, detector=counting)
    frame = mission.platform.capture()
    found = mission.platform.detect(frame, "instance", ["car"])
    assert counting.calls == 1 and mission.platform.detector.name == "counting"
    assert _same(found, counting.inner.detect(frame, "instance", ["car"]))
    with pytest.raises(InvalidInputError, match="'instance' or 'part'"):
        mission.platform.detect(frame, "pixel", ["car"])
    assert counting.calls == 1


class _Reading(_Counting):
    """A detector that reads the image, as a model does."""

    name = "reading"
    reads_image = True


def test_a_detector_that_reads_images_gets_them_in_every_frame() -> None:
    from seminspect.missions.xflie.build import build_mission
    from seminspect.missions.xflie.config import make_config, resolve

    config = resolve(make_config({"world": "campus", "scenario": "small", "seed": 0}))
    default, world = build_mission(config, None)
    truth = TruthDetector(world, noise_preset("ideal"), make_rng(0, "test"))
    assert not reads_image(truth) and not reads_image(_Counting(truth))
    assert default.platform.capture(intensity=False).intensity is None  # the cheaper frame
    reading, _ = build_mission(config, None, world=world, detector=_Reading(truth))
    assert reads_image(reading.platform.detector)
    assert reading.platform.capture(intensity=False).intensity is not None
