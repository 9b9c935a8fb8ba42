"""What Ctrl-C (SIGINT) and SIGTERM do while a file is written: they wait until it is complete.

A ``KeyboardInterrupt`` raised inside the netCDF library's close (xarray holds a lock
there) left the process waiting for that lock for minutes, and SIGTERM left the
hidden temporary file behind. Around a write the two signals are only noted; when
the file is complete and renamed onto its target, the first one noted is acted on:
:class:`WriteInterrupted` (a ``KeyboardInterrupt`` that names the file written) where
Python's handler or the CLI's is installed, the signal's own action otherwise.
"""
from __future__ import annotations

import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

#: The signals a write defers.
DEFERRED = (signal.SIGINT, signal.SIGTERM)


class WriteInterrupted(KeyboardInterrupt):
    """A signal came while ``path`` was written; the file was completed first."""

    def __init__(self, signum: int, path: Path):
        super().__init__(f"{signal.Signals(signum).name} while writing {path}: the file was completed")
        self.signum, self.path = signum, path


@contextmanager
def deferred(path: Path) -> Iterator[None]:
    """Hold SIGINT and SIGTERM while the block runs (the main thread only: signals are delivered there);
    then act on the first one that came (see the module docstring)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    pending: list[int] = []
    previous = {signum: signal.signal(signum, lambda signum, frame: pending.append(signum)) for signum in DEFERRED}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
    if pending:
        handler = previous[pending[0]]
        if callable(handler):
            raise WriteInterrupted(pending[0], path)
        signal.raise_signal(pending[0])  # SIG_DFL: the default action, now that the file is whole
