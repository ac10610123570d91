"""The live view of a policy episode (004, ``seminspect rl show --view``): page and messages.

The page (:func:`episode_page`, on :func:`~seminspect.report.live_common.stream_page`) shows in
3D the room's bounds, its obstacles and the object (meshes, sent once in the scene), a marker
on every object face coloured by what the episode has seen of it (strictly, within the
inspection range, only from farther, never), the path and the robot; beside it what the policy
sees (the object's masked depth) and the status: step and simulated time against the episode's
length, the step's reward and the return, lenient and strict coverage, and how the episode
ended. :class:`EpisodeFeed` turns each :class:`~seminspect.missions.learning.live.LiveState`
into one JSON message for a :class:`~seminspect.report.live_server.LiveServer`.
"""

from __future__ import annotations

import math
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from seminspect.missions.learning.feasibility import face_geometry
from seminspect.missions.learning.live import CRASHED, TIMEOUT, LiveScene, LiveState
from seminspect.missions.learning.rooms import Room
from seminspect.report.live_common import (
    box_edges,
    jpeg_uri,
    mesh,
    scatter,
    stream_page,
    trail,
    xyz,
)
from seminspect.report.live_server import LiveServer

#: Face colours: never seen, seen only from beyond the inspection range, covered (lenient),
#: covered strictly.
UNSEEN, FAR, COVERED, STRICT = "#d62728", "#ff7f0e", "#98df8a", "#2ca02c"


def episode_page(title: str) -> str:
    """The page: the scene's traces empty (the stream fills them), the picture, the status."""
    traces = [
        scatter("room", mode="lines", line={"color": "#999999", "width": 2}),
        mesh("obstacles", "#8c8c8c", 0.35),
        mesh("object", "#c7c7c7", 0.45),
        scatter("faces", hover=True, marker={"size": 5, "color": UNSEEN}),
        scatter("path", mode="lines", line={"color": "#1f77b4", "width": 3}),
        scatter("robot", marker={"symbol": "diamond", "size": 7, "color": "black"}),
    ]
    heading = "Live: the room, the object's faces as they are seen, and the path"
    return stream_page(title, heading, traces, "what the policy sees: the object's depth")


def scene_message(scene: LiveScene) -> dict[str, Any]:
    """The room's bounds, its obstacles and object as meshes, a point per object face."""
    room = scene.room
    target = room.face_of_triangle >= 0
    centres, _, _ = face_geometry(room)
    return {
        "traces": {
            "room": box_edges((0.0, 0.0, 0.0), room.size),
            "obstacles": _mesh(room, ~target & ~_shell(room)),
            "object": _mesh(room, target),
            "faces": {**xyz(centres), "text": _face_text(scene.feasible)},
        },
        "faces": len(centres),
        "feasible": int(scene.feasible.sum()),
    }


class EpisodeFeed:
    """An episode's live states for ``server``, paced by it (a ``LiveFeed``)."""

    def __init__(self, server: LiveServer) -> None:
        self.server = server

    def start(self, scene: LiveScene) -> None:
        self.server.set_scene(scene_message(scene))

    def ready(self) -> bool:
        return self.server.ready()

    def publish(self, state: LiveState) -> None:
        self.server.send(episode_message(state))


def episode_message(state: LiveState) -> dict[str, Any]:
    """One state as the page's JSON (see :mod:`~seminspect.report.live_common`)."""
    covered = state.face_distances <= state.inspect_range
    scored = state.feasible | state.strict  # a face seen strictly was feasible (evaluation)
    return {
        "t": round(state.step / state.control_hz, 2),
        "step": state.step,
        "pose": np.round(state.track[-1, :4], 3).tolist(),
        "reward": round(state.reward, 4),
        "return": round(state.episode_return, 4),
        "coverage": round(state.coverage, 4),
        "covered": int(covered.sum()),
        "strict": int(state.strict.sum()),
        "scored": int(scored.sum()),
        "traces": {
            "path": xyz(trail(state.track[:, :3])),
            "faces": {"color": face_colours(state)},
        },
        "image": _depth_picture(state.depth),
        "caption": f"what the policy sees at step {state.step}: the object's depth, near bright",
        "status": _status(state, int(covered.sum()), int(scored.sum())),
        "final": None if state.ended is None else f"episode {_ending(state)}",
    }


def face_colours(state: LiveState) -> list[str]:
    """Each object face's colour: strict, covered, seen from too far, or never seen."""
    seen = np.isfinite(state.face_distances)
    covered = state.face_distances <= state.inspect_range
    kind = np.where(state.strict, 3, np.where(covered, 2, np.where(seen, 1, 0)))
    palette = (UNSEEN, FAR, COVERED, STRICT)
    return [palette[k] for k in kind]


def _status(state: LiveState, covered: int, scored: int) -> list[list[str]]:
    faces = len(state.face_distances)
    x, y, z, yaw = state.track[-1, :4]
    strict = int(state.strict.sum())
    strict_pct = 100.0 * strict / scored if scored else 100.0
    hz, within = state.control_hz, f"{state.inspect_range:g} m"
    rows = [
        ["step", f"{state.step} / {state.steps_total}"],
        ["simulated", f"{state.step / hz:.1f} / {state.steps_total / hz:.0f} s"],
        ["reward", f"{state.reward:+.3f} (return {state.episode_return:.2f})"],
        [
            "coverage",
            f"{100.0 * state.coverage:.1f} % ({covered} of {faces} faces within {within})",
        ],
        ["strict", f"{strict_pct:.1f} % ({strict} of {scored} feasible faces)"],
        ["robot", f"x {x:.2f}, y {y:.2f}, z {z:.2f} m, yaw {math.degrees(yaw):.0f}°"],
    ]
    if state.ended is not None:
        rows.append(["episode", _ending(state)])
    return rows


def _ending(state: LiveState) -> str:
    if state.ended == CRASHED:
        return f"crashed: struck the {state.struck}" if state.struck else "crashed"
    if state.ended == TIMEOUT:
        return f"timeout: {state.steps_total / state.control_hz:.0f} s flown without a crash"
    return str(state.ended)


def _face_text(feasible: NDArray[np.bool_]) -> list[str]:
    return [f"face {i}{'' if ok else ' (not feasible)'}" for i, ok in enumerate(feasible)]


def _mesh(room: Room, triangles: NDArray[np.bool_]) -> dict[str, list]:
    """The chosen triangles of the room as the page's mesh: vertices and corner indices."""
    chosen = room.triangles[triangles]
    used, corners = np.unique(chosen, return_inverse=True)
    corners = corners.reshape(-1, 3)
    return {
        **xyz(room.vertices[used]),
        "i": corners[:, 0].tolist(),
        "j": corners[:, 1].tolist(),
        "k": corners[:, 2].tolist(),
    }


def _shell(room: Room) -> NDArray[np.bool_]:
    """Triangles of the room's walls, floor and ceiling (all corners on one bounding plane)."""
    corners = room.vertices[room.triangles]
    on_low = np.all(np.abs(corners) < 1e-9, axis=1)
    on_high = np.all(np.abs(corners - room.size) < 1e-9, axis=1)
    return (on_low | on_high).any(axis=1)


def _depth_picture(depth: NDArray[np.float32]) -> str:
    """The masked depth (0 off the object) as a picture, near bright."""
    near = np.where(depth > 0, 1.0 - np.clip(depth, 0.0, 1.0), 0.0)
    picture = cv2.applyColorMap((255 * near).astype(np.uint8), cv2.COLORMAP_BONE)
    return jpeg_uri(picture)
