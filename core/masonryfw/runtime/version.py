"""masonryfw's version: the installed distribution's, or ``0+unknown`` in a source tree that is not installed."""
from __future__ import annotations

from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as _dist_version

try:
    __version__ = _dist_version("masonryfw")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"
