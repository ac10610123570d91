"""The vehicle of the 004 environment: velocity and yaw rate follow their commands (eq (5)).

A first-order loop with time constant tau tracks each command; over a step of dt with the
command held, its response has a closed form, so no integration error builds up.

The state vector s_t (eq (1), 13 values; the observation appends a_{t-1}): position relative
to the room centre divided by the half size, heading (slots 3 to 6), body-frame linear velocity
(m/s), angular velocity (rad/s). Full-angle heading: (cos yaw, 0, 0, sin yaw), continuous at
+-pi; half-angle (v1): the quaternion (w, x, y, z), which flips sign at +-pi, scalar first
unlike seminspect's ``[x, y, z, w]`` poses (:mod:`seminspect.geometry.transforms`), the order
v1 was trained on. The paper's velocities are inertial; body-frame ones keep the whole
observation ego-centric like the maps, which the policy then need not rotate.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from seminspect.geometry.transforms import body_from_world


def first_order_step(
    rate: NDArray[np.float64], command: NDArray[np.float64], dt: float, tau: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """How far a first-order ``rate`` moves its coordinate in ``dt``, and the rate after it.

    ``rate`` (a velocity or yaw rate) relaxes towards ``command`` with time constant ``tau``.
    """
    decay = math.exp(-dt / tau)
    moved = command * dt + (rate - command) * tau * (1.0 - decay)
    return moved, command + (rate - command) * decay


def state_rows(  # noqa: PLR0917 - the vehicle's arrays, positionally
    position: NDArray[np.float64],
    room_size: NDArray[np.float64],
    yaw: NDArray[np.float64],
    velocity: NDArray[np.float64],
    yaw_rate: NDArray[np.float64],
    noise: NDArray[np.float64],
    yaw_encoding: str,
) -> NDArray[np.float64]:
    """``(rows, 13)`` noisy s_t in the layout above; ``noise`` holds 8 values a row (position,
    yaw, velocity, yaw rate) and ``room_size`` each room's own size."""
    half = room_size / 2.0
    state = np.zeros((len(position), 13))
    state[:, 0:3] = (position + noise[:, :3] - half) / half
    # half-angle: (w, x, y, z), scalar first, the policy's order. Not quat_from_yaw ([x, y, z,
    # w], one yaw at a time with math.cos): numpy over the batch is what v1 was trained on.
    heading = yaw + noise[:, 3]
    angle = heading / 2 if yaw_encoding == "half-angle" else heading
    state[:, 3] = np.cos(angle)
    state[:, 6] = np.sin(angle)
    state[:, 7:10] = body_from_world(velocity, yaw) + noise[:, 4:7]
    state[:, 12] = yaw_rate + noise[:, 7]
    return state
