"""Progress reporting shared by the CLI and the solvers.

A solver receives a plain callable ``progress(fraction, message)`` with
``fraction`` in [0, 1]; it never knows whether a bar is shown.
"""
from __future__ import annotations

import re
import shutil
import sys
import threading
import time
from collections.abc import Callable
from typing import TypeVar

#: The type of a progress callback: ``(share done in [0, 1], message) -> None``.
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


class StderrLines:
    """``progress(fraction, message)`` as whole lines ``[ 40%] message`` on a stream nobody watches as a terminal (a
    log file, a CI job, a pipe): the first message, every change of stage (the message without its numbers), and
    otherwise a line each ``step`` of the fraction or each ``interval`` seconds, whichever comes first."""

    def __init__(self, stream, step: float = 0.1, interval: float = 10.0, clock: Callable[[], float] = time.monotonic):
        self.stream, self.step, self.interval, self.clock = stream, step, interval, clock
        self.stage: str | None = None
        self.fraction = 0.0
        self.when = 0.0

    def __call__(self, fraction: float, message: str = "") -> None:
        done = min(max(float(fraction), 0.0), 1.0)
        stage = _NUMBER.sub("#", message)
        now = self.clock()
        if stage == self.stage and done < self.fraction + self.step and now < self.when + self.interval:
            return
        self.stage, self.fraction, self.when = stage, done, now
        self.stream.write(f"[{done:4.0%}] {message}\n")
        self.stream.flush()

    def close(self) -> None:
        """Nothing to end: every line is whole."""


_NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


def progress_bar(wanted: bool | None) -> StderrBar | StderrLines | None:
    """Progress on stderr: with ``--no-progress`` none; with ``--progress``, or by default on a terminal, a bar;
    by default elsewhere (a log, a pipe), lines (:class:`StderrLines`)."""
    if wanted is False:
        return None
    return StderrBar(sys.stderr) if wanted or sys.stderr.isatty() else StderrLines(sys.stderr)
