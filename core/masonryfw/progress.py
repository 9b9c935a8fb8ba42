"""Progress reporting shared by the CLI and the solvers.

A solver receives a plain callable ``progress(fraction, message)`` with
``fraction`` in [0, 1]; it never knows whether a bar is shown.
"""
from __future__ import annotations

from collections.abc import Callable

ProgressCallback = Callable[[float, str], None]


def no_progress(fraction: float, message: str = "") -> None:
    """The progress callback that shows nothing."""
