"""bench/mission.py judges a mission's real-time factor against the target of its mission."""

from bench_scripts import bench_script


def _script():
    return bench_script("mission")


def test_the_default_mission_is_held_to_fifty_times_real_time() -> None:
    script = _script()
    target = script.TARGET_FACTORS[("city", "medium")]
    assert script.target_verdict(54.0, target) == " (target 50x: met)"
    assert script.target_verdict(49.9, target) == " (target 50x: missed)"
    large = script.TARGET_FACTORS[("city", "large")]
    assert script.target_verdict(21.0, large) == " (target 20x: met)"


def test_a_mission_without_a_target_gets_no_verdict() -> None:
    script = _script()
    assert script.target_verdict(80.0, script.TARGET_FACTORS.get(("tunnel", "small"))) == ""
