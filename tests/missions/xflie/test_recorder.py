from fake_platform import EventList
from seminspect.missions.xflie.metrics import CoverageRecorder
from seminspect.missions.xflie.recorder import MissionRecorder


def test_events_are_stamped_with_the_mission_clock() -> None:
    clock = {"t": 0.0}
    sink = EventList()
    recorder = MissionRecorder(lambda: clock["t"], CoverageRecorder(2.5), sink)
    recorder.event("detected", target="car-0")
    clock["t"] = 12.5
    recorder.event("arrived", target="car-0")
    assert [(e["t"], e["event"]) for e in sink.events] == [(0.0, "detected"), (12.5, "arrived")]
    MissionRecorder(lambda: 0.0, CoverageRecorder(2.5)).event("dropped")  # no sink: no error


def test_the_record_counts_level_endings_and_is_a_snapshot() -> None:
    recorder = MissionRecorder(lambda: 0.0, CoverageRecorder(2.5))
    recorder.level_ended("similarity")
    recorder.level_ended("cap")
    recorder.level_ended("similarity")
    with recorder.timers("sensing"):
        pass
    record = recorder.record()
    assert (record.level_endings.similarity, record.level_endings.cap) == (2, 1)
    assert list(record.seconds_by_category) == ["sensing"]
    recorder.level_ended("cap")
    assert record.level_endings.cap == 1  # later endings do not change an earlier record
    assert record.plans == [] and recorder.plans == []
