import math

import numpy as np

from fake_platform import CAMERA, FakePlatform, fake_context
from seminspect.missions.xflie.completion import LEVEL_SWEEP_CAP, LevelCompletion, LevelState

CENTRE = np.array([0.0, 0.0, 0.7])
RADIUS = 3.0


def textured(seed: int) -> np.ndarray:
    """A random texture: images of one seed match, images of two seeds do not."""
    rng = np.random.default_rng(seed)
    coarse = rng.integers(0, 255, (CAMERA.height // 4, CAMERA.width // 4), dtype=np.uint8)
    return np.kron(coarse, np.ones((4, 4), np.uint8))


def ring_views(ctx, completion, state, count, *, step_deg=30.0, image=None) -> list[bool]:
    """Views ``step_deg`` apart on a 6 m circle around the centre (wider than ``d_thresh^I``),
    starting at the level's start; the image depends on the view's index."""
    platform = ctx.platform
    ends = []
    for k in range(count):
        angle = math.pi + math.radians(step_deg) * k
        platform.move_to(CENTRE + RADIUS * np.array([math.cos(angle), math.sin(angle), 0.0]))
        platform.image = lambda position, yaw, k=k: textured(k if image is None else image(k))
        state.poses += 1
        ends.append(completion.is_complete(state, platform.capture(), "car-0", CENTRE))
    return ends


def start_state(platform: FakePlatform) -> LevelState:
    platform.move_to(CENTRE + np.array([-RADIUS, 0.0, 0.0]))
    return LevelState(platform.position)


def test_the_first_n_views_become_the_candidates_and_never_end_the_level() -> None:
    ctx, _ = fake_context()
    completion = LevelCompletion(ctx)
    state = start_state(ctx.platform)
    ends = ring_views(ctx, completion, state, ctx.params.horizon_N)
    assert not any(ends)
    assert len(state.candidates) == ctx.params.horizon_N


def test_back_at_the_start_the_same_view_ends_the_level_by_eq_8() -> None:
    ctx, events = fake_context()
    completion = LevelCompletion(ctx)
    state = start_state(ctx.platform)
    # around the ring, then the first view's scene again from the start
    ends = ring_views(ctx, completion, state, 13, image=lambda k: k % 12)
    assert ends[-1] and not any(ends[:-1])
    assert state.left_start
    assert ctx.recorder.record().level_endings.similarity == 1
    ending = events.events[-1]
    assert ending["event"] == "level-complete" and ending["reason"] == "similarity"
    assert ending["gamma"] >= completion.gamma_thresh


def test_new_scenes_all_the_way_round_end_the_level_by_the_sweep_cap() -> None:
    ctx, events = fake_context()
    completion = LevelCompletion(ctx)
    state = start_state(ctx.platform)
    ends = ring_views(ctx, completion, state, 24, step_deg=18.0, image=lambda k: 100 + k)
    assert ends.index(True) == 23  # 360 + 40 degrees at 18 degrees a view
    assert state.sweep >= LEVEL_SWEEP_CAP
    assert ctx.recorder.record().level_endings.cap == 1
    assert events.events[-1]["reason"] == "cap"


def test_the_pose_cap_ends_a_level_that_goes_nowhere() -> None:
    ctx, _ = fake_context(settings={"inspection": {"max_poses_per_level": 5}})
    completion = LevelCompletion(ctx)
    state = start_state(ctx.platform)
    ends = [
        completion.is_complete(state, ctx.platform.capture(), "car-0", CENTRE)
        for state.poses in range(1, 8)
    ]
    assert ends.index(True) == 4 and state.sweep == 0.0
