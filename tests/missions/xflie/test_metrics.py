import numpy as np

from seminspect.missions.xflie.metrics import CoverageRecorder
from seminspect.sensors import CameraModel, Frame


def _frame(face: np.ndarray, depth: np.ndarray) -> Frame:
    shape = face.shape
    return Frame(
        depth=depth.astype(np.float32),
        instance=np.zeros(shape, np.int32),
        class_id=np.zeros(shape, np.int16),
        part_id=np.zeros(shape, np.int16),
        intensity=np.zeros(shape, np.uint8),
        face=face.astype(np.int32),
        position=np.zeros(3),
        orientation=np.array([0.0, 0.0, 0.0, 1.0]),
        stamp=0.0,
        camera=CameraModel(shape[1], shape[0]),
    )


def test_a_frame_adds_the_faces_it_saw_up_close_face_zero_included() -> None:
    rng = np.random.default_rng(0)
    recorder = CoverageRecorder(d_view=2.0)
    seen: set[int] = set()
    for _ in range(3):
        face = rng.integers(-1, 5000, (48, 64))
        depth = rng.uniform(0.5, 2 * recorder.max_range, face.shape)
        face[0, 0], depth[0, 0] = 0, 1.0  # the mesh's first face
        recorder.add_frame("car-1", _frame(face, depth), np.zeros((0, 3)))
        close = (face >= 0) & (depth.astype(np.float32) <= recorder.max_range)
        seen |= set(np.unique(face[close]).tolist())
    assert recorder.targets["car-1"].faces == seen
    assert 0 in seen and -1 not in seen
