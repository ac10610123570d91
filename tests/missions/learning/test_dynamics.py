"""The first-order velocity loop of the 004 vehicle against its exponential solution."""

import math

import numpy as np
import pytest

from seminspect.missions.learning.dynamics import first_order_step


def test_one_step_is_the_exact_exponential_response():
    rate, command, dt, tau = np.array([0.0, 2.0]), np.array([1.0, 1.0]), 0.1, 0.2
    moved, after = first_order_step(rate, command, dt, tau)
    decay = math.exp(-dt / tau)
    np.testing.assert_allclose(after, command + (rate - command) * decay)
    # the distance is the integral of the rate over the step
    t = np.linspace(0.0, dt, 10_001)
    integral = np.trapezoid(command[0] + (rate[0] - command[0]) * np.exp(-t / tau), t)
    assert moved[0] == pytest.approx(integral, rel=1e-7)


def test_many_small_steps_make_one_big_one():
    rate, command = np.array([0.3]), np.array([-1.0])
    moved_once, after_once = first_order_step(rate, command, 1.0, 0.2)
    total = np.zeros(1)
    for _ in range(10):
        moved, rate = first_order_step(rate, command, 0.1, 0.2)
        total += moved
    np.testing.assert_allclose(total, moved_once)
    np.testing.assert_allclose(rate, after_once)
