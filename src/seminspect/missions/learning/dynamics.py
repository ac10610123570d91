"""The vehicle of the 004 environment: velocity and yaw rate follow their commands (eq (5)).

A first-order loop with time constant tau tracks each command; over a step of dt with the
command held, its response has a closed form, so no integration error builds up.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray


def first_order_step(
    rate: NDArray[np.float64], command: NDArray[np.float64], dt: float, tau: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """How far a first-order ``rate`` moves its coordinate in ``dt``, and the rate after it.

    ``rate`` (a velocity or yaw rate) relaxes towards ``command`` with time constant ``tau``.
    """
    decay = math.exp(-dt / tau)
    moved = command * dt + (rate - command) * tau * (1.0 - decay)
    return moved, command + (rate - command) * decay
