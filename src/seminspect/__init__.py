"""seminspect: semantic-aware autonomous inspection robots in simulation and on real data.

The package is layered (see ``docs/architecture.md``); data flows one way:
worlds and sensors -> perception -> mapping and scene graphs -> planning -> missions -> CLI
and reports.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("seminspect")
except PackageNotFoundError:  # running from a source tree without an install
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
