"""The robot as the programs see it: the `Platform` protocol and its simulated implementation."""

from seminspect.platform.protocol import Motion, Platform, heading_to
from seminspect.platform.simulated import SimulatedPlatform

__all__ = ["Motion", "Platform", "SimulatedPlatform", "heading_to"]
