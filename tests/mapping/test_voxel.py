import math
import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from seminspect.core.errors import FileFormatError, InvalidInputError
from seminspect.core.io import save_npz_atomic
from seminspect.geometry.transforms import quat_from_yaw
from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN, VoxelMap, load_map, save_map
from seminspect.sensors import CameraModel, Lidar, LidarScan, render
from sim_worlds import box_world


def test_index_round_trip_and_bounds() -> None:
    grid = VoxelMap.empty([-1.0, -2.0, 0.0], [1.0, 2.0, 1.0], 0.5)
    assert grid.shape == (4, 8, 2)
    np.testing.assert_allclose(grid.upper, [1.0, 2.0, 1.0])
    centre = grid.index_to_world([1, 3, 0])
    np.testing.assert_allclose(centre, [-0.25, -0.25, 0.25])
    assert grid.world_to_index(centre).tolist() == [1, 3, 0]


def test_state_lookup_marks_outside_points() -> None:
    grid = VoxelMap.empty([0, 0, 0], [1, 1, 1], 0.5)
    grid.states[0, 0, 0] = OCCUPIED
    grid.states[1, 1, 1] = FREE
    states = grid.state_at([[0.1, 0.1, 0.1], [0.9, 0.9, 0.9], [5, 5, 5]], outside=OCCUPIED)
    assert states.tolist() == [OCCUPIED, FREE, OCCUPIED]
    assert grid.counts() == {"unknown": 6, "free": 1, "occupied": 1}
    assert UNKNOWN == 0


@pytest.mark.parametrize(
    ("lower", "upper", "res"),
    [
        ([0, 0, 0], [1, 1, 1], 0.0),
        ([0, 0, 0], [0, 1, 1], 0.1),
        ([0, 0, float("nan")], [1, 1, 1], 0.1),
    ],
)
def test_impossible_maps_are_refused(lower, upper, res) -> None:
    with pytest.raises(InvalidInputError):
        VoxelMap.empty(lower, upper, res)


def test_huge_map_is_refused_before_allocating() -> None:
    with pytest.raises(InvalidInputError, match="coarser"):
        VoxelMap.empty([0, 0, 0], [10_000, 10_000, 100], 0.01)


# ----------------------------------------------------------------- ray integration
def test_a_hit_clears_its_ray_and_occupies_its_end() -> None:
    grid = VoxelMap.empty([0, 0, 0], [10, 1, 1], 1.0)
    grid.integrate_rays([0.5, 0.5, 0.5], [[7.5, 0.5, 0.5]], [True])
    assert grid.states[:, 0, 0].tolist() == [FREE] * 7 + [OCCUPIED, UNKNOWN, UNKNOWN]
    grid.integrate_rays([0.5, 0.5, 0.5], [[9.5, 0.5, 0.5]], [False])  # a miss clears to its end
    assert grid.states[:, 0, 0].tolist() == [FREE] * 7 + [OCCUPIED, FREE, FREE]  # sticky


def test_rays_are_clipped_to_the_map() -> None:
    grid = VoxelMap.empty([0, 0, 0], [4, 4, 1], 1.0)
    grid.integrate_rays([[-5.0, 0.5, 0.5]], [[2.5, 0.5, 0.5]], [True])  # enters from outside
    assert grid.states[:, 0, 0].tolist() == [FREE, FREE, OCCUPIED, UNKNOWN]
    grid.integrate_rays([[0.5, 1.5, 0.5]], [[9.0, 1.5, 0.5]], [True])  # hit beyond the map
    assert grid.states[:, 1, 0].tolist() == [FREE] * 4
    grid.integrate_rays([[-5.0, -5.0, 0.5]], [[-1.0, 9.0, 0.5]], [True])  # never inside
    assert grid.counts()["free"] == 6
    grid.integrate_rays([0, 0, 0], np.zeros((0, 3)), [])  # nothing to do


@pytest.mark.parametrize(
    ("origins", "ends", "hit"),
    [
        ([0, 0, 0], [[1, 1, 1]], [True, False]),
        (np.zeros((2, 3)), [[1, 1, 1]], [True]),
        ([0, 0, math.nan], [[1, 1, 1]], [True]),
        ([0, 0, 0], [[1, 1]], [True]),
    ],
)
def test_bad_rays_are_refused(origins, ends, hit) -> None:
    with pytest.raises(InvalidInputError):
        VoxelMap.empty([0, 0, 0], [2, 2, 2], 1.0).integrate_rays(origins, ends, hit)


coordinate = st.floats(-1.0, 6.0, allow_nan=False)


@settings(max_examples=80, deadline=None)
@given(st.tuples(coordinate, coordinate, coordinate), st.tuples(coordinate, coordinate, coordinate))
def test_traversal_marks_only_cells_on_the_segment(start, end) -> None:
    grid = VoxelMap.empty([0, 0, 0], [5, 5, 5], 1.0)
    a, b = np.array(start), np.array(end)
    grid.integrate_rays(a, [b], [True])
    marked = np.argwhere(grid.states != UNKNOWN) + 0.5
    if len(marked):
        # every marked cell centre lies within half a cell diagonal of the segment
        direction = b - a
        t = np.clip(((marked - a) @ direction) / max(direction @ direction, 1e-12), 0.0, 1.0)
        gap = np.linalg.norm(a + t[:, None] * direction - marked, axis=1)
        assert gap.max() <= math.sqrt(3) / 2 + 1e-6
    reached = a + (b - a)  # the end as the kernel computes it (to the last bit)
    if np.all((reached >= 0) & (reached < 5)):
        assert grid.state_at(reached) == OCCUPIED
    if np.all((a >= 0) & (a < 5)) and not np.array_equal(np.floor(a), np.floor(reached)):
        assert grid.state_at(a) == FREE


# ----------------------------------------------------------------- maps from worlds and sensors
@pytest.fixture(scope="module")
def wall_world():
    return box_world(lower=(5.0, -3.0, 0.0), upper=(6.0, 3.0, 3.0), size=(20.0, 12.0, 4.0))


def test_map_from_the_world(wall_world) -> None:
    truth = VoxelMap.from_world(wall_world, 0.25)
    assert truth.origin[2] == pytest.approx(-0.125)  # the ground runs through the bottom layer
    assert (truth.states[:, :, 0] == OCCUPIED).all() and (truth.states[:, :, 1:] != UNKNOWN).all()
    assert truth.state_at([[5.6, 0.1, 1.5], [5.0, 0.0, 1.0], [3.0, 0.0, 1.0]]).tolist() == [
        FREE,  # inside the solid box: only cells touching its surface are occupied
        OCCUPIED,
        FREE,
    ]
    boxed = VoxelMap.from_world(wall_world, 0.5, bounds=[(0, -2, 0.5), (4, 2, 2)])
    assert boxed.counts()["occupied"] == 0


def test_depth_frames_agree_with_the_world(wall_world) -> None:
    truth = VoxelMap.from_world(wall_world, 0.2)
    grid = VoxelMap.covering(wall_world, 0.2)
    for yaw in (-0.4, 0.0, 0.4):
        frame = render(wall_world, CameraModel(), (0.0, 0.0, 1.0), quat_from_yaw(yaw))
        grid.integrate_frame(frame, stride=4)
    occupied = grid.states == OCCUPIED
    free = grid.states == FREE
    assert occupied.sum() > 500 and free.sum() > 20_000
    assert (truth.states[occupied] == OCCUPIED).mean() > 0.99
    assert (truth.states[free] == FREE).mean() > 0.97
    assert grid.state_at([7.0, 0.0, 1.0]) == UNKNOWN  # behind the wall
    assert grid.state_at([2.0, 0.0, 1.0]) == FREE


def test_odometry_frames_and_lidar_scans(wall_world) -> None:
    frame = render(
        wall_world,
        CameraModel(160, 120),
        (0.0, 0.0, 1.0),
        quat_from_yaw(0.0),
        odometry=((0.0, 1.0, 1.0), quat_from_yaw(0.0)),
    )
    true_map, believed = VoxelMap.covering(wall_world, 0.2), VoxelMap.covering(wall_world, 0.2)
    true_map.integrate_frame(frame, stride=1)
    believed.integrate_frame(frame, stride=1, use_odometry=True)
    assert believed.state_at([5.1, 3.6, 1.0]) == OCCUPIED  # the wall edge, shifted by 1 m
    assert true_map.state_at([5.1, 3.6, 1.0]) != OCCUPIED
    scan = Lidar(horizontal_resolution_deg=1.0).scan(wall_world, (0.0, 0.0, 1.0), quat_from_yaw(0))
    lidar_map = VoxelMap.covering(wall_world, 0.2)
    lidar_map.integrate_scan(scan)
    assert lidar_map.state_at([5.05, 0.0, 1.0]) == OCCUPIED
    assert lidar_map.counts()["occupied"] > 300
    with pytest.raises(InvalidInputError, match="stride"):
        true_map.integrate_frame(frame, stride=0)


def test_inflation_grows_occupied_cells_by_a_radius() -> None:
    grid = VoxelMap.empty([0, 0, 0], [3, 3, 3], 0.1)
    grid.states[15, 15, 15] = OCCUPIED
    grid.states[0, 0, 0] = FREE
    inflated = grid.inflated(0.2)
    grown = np.argwhere(inflated.states == OCCUPIED)
    assert len(grown) == 33  # the cells within two cell lengths of the centre
    assert np.abs(grown - 15).max() == 2
    assert inflated.states[0, 0, 0] == FREE and grid.counts()["occupied"] == 1
    assert grid.inflated(0.05).counts() == grid.counts()
    with pytest.raises(InvalidInputError):
        grid.inflated(-1.0)


@pytest.mark.parametrize(
    ("start", "end"),
    [
        ((0.0, 1.0, 0.0), (0.0, 0.0, 1.0)),
        ((1.0, 1.0, 1.0), (2.0, 2.0, 2.0)),
        ((3, 0, 0), (0, 3, 0)),
    ],
)
def test_rays_along_cell_edges_still_occupy_their_end(start, end) -> None:
    grid = VoxelMap.empty([0, 0, 0], [5, 5, 5], 1.0)
    grid.integrate_rays(start, [end], [True])
    assert grid.state_at(end) == OCCUPIED


def test_lidar_misses_clear_free_space_only_when_asked() -> None:
    from seminspect.sensors import Lidar
    from seminspect.worlds import generate_world

    world = generate_world("city", "small", seed=0)
    start = world.start_position + np.array([0.0, 0.0, 0.7])
    scan = Lidar(max_range=30.0).scan(world, start, [0, 0, 0, 1])
    assert len(scan.misses) > 0  # upward beams see open sky
    plain = VoxelMap.covering(world, 0.5)
    plain.integrate_scan(scan)
    cleared = VoxelMap.covering(world, 0.5)
    cleared.integrate_scan(scan, clear_misses_to=20.0)
    assert cleared.counts()["free"] > plain.counts()["free"]
    assert cleared.counts()["occupied"] == plain.counts()["occupied"]
    above = start + np.array([10.0, 0.0, 2.4])  # open sky, on a 13-degree beam
    assert plain.state_at([above])[0] == UNKNOWN and cleared.state_at([above])[0] == FREE
    with pytest.raises(InvalidInputError, match="clear_misses_to"):
        cleared.integrate_scan(scan, clear_misses_to=50.0)


def test_boxes_occupy_the_cells_they_overlap() -> None:
    grid = VoxelMap.from_boxes([0, 0, 0], [4, 4, 2], 0.5, [[[1.2, 1.2, 0.0], [2.0, 1.4, 0.8]]])
    occupied = np.argwhere(grid.states == OCCUPIED)
    assert {tuple(c) for c in occupied} == {(i, 2, k) for i in (2, 3) for k in (0, 1)}
    assert grid.counts()["unknown"] == 0
    with pytest.raises(InvalidInputError, match="finite"):
        VoxelMap.from_boxes([0, 0, 0], [4, 4, 2], 0.5, [[[0, 0, 0], [1, 1, float("inf")]]])


@settings(max_examples=40, deadline=None)
@given(
    st.integers(0, 2**16),
    st.sampled_from([(0.2, 0.5), (0.3, 0.4), (0.3, 0.7), (0.25, 0.25)]),
)
def test_coarsening_keeps_every_obstacle_and_invents_none(seed, resolutions) -> None:
    fine_res, coarse_res = resolutions
    rng = np.random.default_rng(seed)
    fine = VoxelMap.empty([-1.0, 0.5, 0.0], [3.1, 4.0, 1.9], fine_res)
    fine.states[:] = rng.choice([UNKNOWN, FREE, OCCUPIED], size=fine.shape, p=[0.3, 0.65, 0.05])
    coarse = fine.coarsened(coarse_res)
    np.testing.assert_allclose(coarse.origin, fine.origin)
    assert np.all(coarse.upper >= fine.upper - 1e-9)
    centres = fine.index_to_world(np.argwhere(np.ones(fine.shape, bool)))
    # every fine cell's centre lies in a coarse cell of at least its state
    held = coarse.state_at(centres).reshape(fine.shape)
    assert np.all(held >= fine.states)
    # a coarse cell is occupied only when an occupied fine cell overlaps it
    for cell in np.argwhere(coarse.states == OCCUPIED):
        lo = coarse.origin + cell * coarse_res
        hi = lo + coarse_res
        f_lo = np.floor((lo - fine.origin) / fine_res + 1e-9).astype(int)
        f_hi = np.ceil((hi - fine.origin) / fine_res - 1e-9).astype(int)
        block = fine.states[f_lo[0] : f_hi[0], f_lo[1] : f_hi[1], f_lo[2] : f_hi[2]]
        assert (block == OCCUPIED).any()
    with pytest.raises(InvalidInputError, match="coarser"):
        fine.coarsened(fine_res / 2)


def test_maps_round_trip_and_bad_files_are_refused(tmp_path) -> None:
    grid = VoxelMap.empty([0, 0, -0.1], [2, 1, 1], 0.25)
    grid.states[1, 2, 3] = OCCUPIED
    grid.states[0] = FREE
    loaded = load_map(save_map(tmp_path / "map.npz", grid))
    np.testing.assert_array_equal(loaded.states, grid.states)
    np.testing.assert_allclose(loaded.origin, grid.origin)
    assert loaded.resolution == grid.resolution
    (tmp_path / "junk.npz").write_bytes(b"not a zip")
    with pytest.raises(FileFormatError, match=r"junk\.npz"):
        load_map(tmp_path / "junk.npz")
    np.savez(tmp_path / "other.npz", states=grid.states)
    with pytest.raises(FileFormatError, match="not a seminspect voxel map"):
        load_map(tmp_path / "other.npz")
    save_npz_atomic(
        tmp_path / "bad.npz",
        format=np.array("seminspect.voxel-map"),
        version=np.array(1),
        origin=grid.origin,
        resolution=np.array(0.25),
        states=np.full((2, 2, 2), 7, np.uint8),
    )
    with pytest.raises(FileFormatError, match="0, 1, 2"):
        load_map(tmp_path / "bad.npz")


def test_a_map_over_a_strided_view_is_kept_c_ordered_and_integrates_rays() -> None:
    wide = np.zeros((8, 6, 4), dtype=np.uint8)
    grid = VoxelMap(np.zeros(3), 0.5, wide[::2])
    assert grid.states.flags.c_contiguous and grid.shape == (4, 6, 4)
    grid.integrate_rays([0.1, 0.1, 0.1], [[1.9, 0.1, 0.1]], [True])
    assert grid.states[3, 0, 0] == OCCUPIED and grid.states[:3, 0, 0].tolist() == [FREE] * 3


def _frames_and_scans(world):
    """Frames and scans from a few poses, in the order a robot would take them."""
    lidar = Lidar(horizontal_resolution_deg=1.0)
    for x, yaw in ((0.0, -0.3), (1.0, 0.0), (2.0, 0.3)):
        pose = ((x, 0.0, 1.0), quat_from_yaw(yaw))
        yield render(world, CameraModel(160, 120), *pose)
        yield lidar.scan(world, *pose)


def _integrate(voxel_map, reading) -> None:
    if isinstance(reading, LidarScan):
        voxel_map.integrate_scan(reading, clear_misses_to=10.0)
    else:
        voxel_map.integrate_frame(reading, stride=2)


def test_background_integration_gives_the_same_map_in_the_same_order(wall_world) -> None:
    in_place, background = VoxelMap.covering(wall_world, 0.2), VoxelMap.covering(wall_world, 0.2)
    background.background = True
    for reading in _frames_and_scans(wall_world):
        _integrate(in_place, reading)
        _integrate(background, reading)
        # Every read waits for the walks handed over before it.
        np.testing.assert_array_equal(background.states, in_place.states)
    assert in_place.counts()["occupied"] > 300


def test_a_map_with_walks_pending_waits_before_it_is_written_or_pickled(wall_world) -> None:
    expected = VoxelMap.covering(wall_world, 0.2)
    readings = list(_frames_and_scans(wall_world))
    for reading in readings:
        _integrate(expected, reading)
    voxel_map = VoxelMap.covering(wall_world, 0.2)
    voxel_map.background = True
    for reading in readings:
        _integrate(voxel_map, reading)
    copy = pickle.loads(pickle.dumps(voxel_map))
    np.testing.assert_array_equal(copy.states, expected.states)
    assert not copy.background  # an unpickled map integrates in place until told otherwise
    fresh = VoxelMap.covering(wall_world, 0.2)
    fresh.background = True
    cells = fresh.states  # the array the walks will write into
    for reading in readings:
        _integrate(fresh, reading)
    fresh.states = np.zeros_like(cells)  # replaced once the walks are done, not during
    np.testing.assert_array_equal(cells, expected.states)
    assert fresh.counts()["unknown"] == cells.size
