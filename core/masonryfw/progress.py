"""Progress reporting shared by the CLI and the solvers.

A solver receives a plain callable ``progress(fraction, message)`` with
``fraction`` in [0, 1]; it never knows whether a bar is shown.
"""
from __future__ import annotations

import shutil
import sys
import threading
from collections.abc import Callable
from typing import TypeVar

ProgressCallback = Callable[[float, str], None]
T = TypeVar("T")


def no_progress(fraction: float, message: str = "") -> None:
    """The progress callback that shows nothing."""


def interruptible(call: Callable[[], T]) -> T:
    """``call()`` in a daemon thread, the caller waiting: Ctrl-C reaches Python while the call runs.

    A long call into compiled code that releases the GIL (Clarabel's solve, for one) does not
    return to the interpreter, so a KeyboardInterrupt waits for its end (jmm-limit on a 10,000-unit
    wall ignored Ctrl-C for 10 minutes). Here the main thread waits in short ``join``s and takes the
    interrupt at once; the abandoned call runs on until the process exits. A call that holds the GIL
    gains nothing but loses nothing either.
    """
    outcome: list = []

    def run() -> None:
        try:
            outcome.append((True, call()))
        except BaseException as exc:  # handed to the caller
            outcome.append((False, exc))

    worker = threading.Thread(target=run, name="masonryfw-interruptible", daemon=True)
    worker.start()
    while worker.is_alive():
        worker.join(0.1)
    ok, value = outcome[0]
    if not ok:
        raise value
    return value


class StderrBar:
    """``progress(fraction, message)`` drawn as one line ``[####......]  40% message`` on a stream, as wide as
    the terminal: a message that does not fit loses words from its middle (``...``), never its end, where the
    solvers put the numbers (a reaction, a settlement)."""

    width = 20

    def __init__(self, stream, columns: int | None = None):
        self.stream = stream
        self.columns = columns or shutil.get_terminal_size((80, 24)).columns
        self.drawn = False

    def __call__(self, fraction: float, message: str = "") -> None:
        done = min(max(float(fraction), 0.0), 1.0)
        filled = round(done * self.width)
        bar = "#" * filled + "." * (self.width - filled)
        head = f"[{bar}] {done:4.0%} "
        room = max(self.columns - len(head) - 1, 10)
        self.stream.write(f"\r{head}{fitted(message, room):<{room}}")
        self.stream.flush()
        self.drawn = True

    def close(self) -> None:
        if self.drawn:
            self.stream.write("\n")
            self.stream.flush()


def fitted(message: str, room: int) -> str:
    """``message`` in at most ``room`` characters: its start and its end kept, the middle replaced by ``...``."""
    if len(message) <= room:
        return message
    keep = room - 3
    tail = (keep + 1) // 2
    return message[:keep - tail] + "..." + message[len(message) - tail:]


def progress_bar(wanted: bool | None) -> StderrBar | None:
    """A bar on stderr: with ``--progress`` always, with ``--no-progress`` never, else when stderr is a terminal."""
    show = sys.stderr.isatty() if wanted is None else wanted
    return StderrBar(sys.stderr) if show else None
