from fake_platform import FakePlatform, fake_context
from seminspect.missions.xflie import XFlie


def test_an_empty_known_site_ends_after_one_survey_with_its_reason() -> None:
    ctx, _ = fake_context()  # only for its configuration and map
    platform = FakePlatform()
    phases = []
    mission = XFlie(
        ctx.config,
        platform,
        ctx.occupancy,
        ground_z=0.0,
        progress=lambda progress: phases.append(progress.phase),
    )
    assert mission.execute() == "no uninspected target and no frontier left"
    assert platform.frames > 0 and platform.scans == 1
    assert phases[0] == "explore-360" and "explore-frontier" in phases
    assert not mission.graph.targets() and not mission.unreachable


def test_a_mission_out_of_time_stops_for_the_budget() -> None:
    ctx, _ = fake_context()
    platform = FakePlatform()
    platform.wait(ctx.config.time_budget_s)
    mission = XFlie(ctx.config, platform, ctx.occupancy, ground_z=0.0)
    assert mission.execute() == "time budget spent"
    assert platform.frames == 0
