"""What Ctrl-C (SIGINT) and SIGTERM do: the command line's handlers, signals held where an exception would do
harm, interrupts that are not lost, and the moment a command's outcome is settled.

**The command line** (:func:`install`) takes both signals alike from its first line: SIGINT raises
``KeyboardInterrupt``, SIGTERM :class:`Terminated` (one), and each is remembered, so the command ends with
``128 + signal`` (:func:`exit_status`) and a line saying what was kept. A signal the process inherited as
ignored stays ignored, as Python itself leaves it: a shell script's background job ignores SIGINT, so that a
Ctrl-C meant for the foreground does not stop it; SIGTERM still does.

**Settled** (:func:`settle`): a command's outcome is settled when the last of the outputs it claimed before
its work (:mod:`masonryfw.runtime.locks`) is about to be renamed into place, or when the command ends. From then on a
signal changes nothing: the command says what it did and exits with its own status (0 with a complete result;
during the interpreter's shutdown the process ends at once with that status). The boundary is the rename of
the last output, which a test can observe from outside, so what a signal does never depends on how fast the
process runs: a signal while the file is still being written gives 130 (143) and the complete file; one
once it is in place gives exit 0 and the same file.

**Held** (:func:`signals_held`): some code must not be cut at an arbitrary instruction. A ``KeyboardInterrupt``
raised inside the netCDF library's close (xarray holds a lock there) left the process waiting for that lock
for minutes, and SIGTERM left the hidden temporary file behind; one raised inside numba's compilation, in
LLVM's callback into llvmlite, was dropped and lost the compiled code ("no compiled object yet"). While
held, the two signals are only noted; the first is acted on, as the handler before would have, at a
checkpoint the code chooses or when the block ends. :func:`deferred` holds a write until the file is
complete and renamed onto its target, then raises :class:`WriteInterrupted` (a ``KeyboardInterrupt`` that
names the file written) where Python's handler or the command line's is installed, and takes the signal's
own action otherwise. A signal noted once the outcome is settled is dropped.

**Dropped** interrupts: Python code run from a finalizer, a weakref callback or a C callback cannot raise; a
``KeyboardInterrupt`` raised there is printed and dropped. The command line's hook of unraisable exceptions
sends such a signal again, from a helper thread, to be taken where it can be.
"""
from __future__ import annotations

import atexit
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

#: The signals a command answers (and holds).
DEFERRED = (signal.SIGINT, signal.SIGTERM)

#: The signals the command line's handlers have taken, in order (the exit status follows the first).
RECEIVED: list[int] = []
#: The files completed (renamed onto their targets) since the command began, in order: what an interrupted
#: command says it kept.
WRITTEN: list[Path] = []


class _Command:
    """Whether the command line's handlers are installed, and whether its outcome is settled."""

    answering = False
    settled = False


class Terminated(KeyboardInterrupt):
    """SIGTERM, taken as Ctrl-C is: what an interrupted command keeps, it keeps; temporary files are removed."""


class WriteInterrupted(KeyboardInterrupt):
    """A signal came while ``path`` was written; the file was completed first."""

    def __init__(self, signum: int, path: Path):
        super().__init__(f"{signal.Signals(signum).name} while writing {path}: the file was completed")
        self.signum, self.path = signum, path


def _take(signum: int, frame) -> None:
    RECEIVED.append(signum)
    raise Terminated if signum == signal.SIGTERM else KeyboardInterrupt


def install() -> None:
    """A command begins: the command line's handlers of SIGINT and SIGTERM (the main thread only, as Python
    requires), its hook of dropped interrupts, nothing received or written yet."""
    RECEIVED.clear()
    WRITTEN.clear()
    _Command.answering, _Command.settled = True, False
    for signum in _answered():
        signal.signal(signum, _take)
    if not isinstance(sys.unraisablehook, _SendAgain):
        sys.unraisablehook = _SendAgain(sys.unraisablehook)
        atexit.register(_ignore)  # the first registered, run last


def exit_status() -> int:
    """``128 +`` the first signal taken (130 after Ctrl-C, 143 after SIGTERM), as shells report it."""
    return 128 + (RECEIVED[0] if RECEIVED else signal.SIGINT)


def kept() -> str:
    """What an interrupted command kept, in words: the files it completed, or nothing."""
    return f"interrupted after writing {', '.join(map(str, WRITTEN))} (complete)" if WRITTEN else \
        "interrupted: nothing written"


def settle() -> None:
    """The command's outcome is settled (see the module docstring): SIGINT and SIGTERM, where answered, are
    dropped from now on, and a signal noted while a write is held is dropped. Outside the command line (no
    :func:`install`), nothing changes: a script's Ctrl-C is never dropped."""
    if not _Command.answering or threading.current_thread() is not threading.main_thread():
        return
    _Command.settled = True
    for signum in _answered():
        signal.signal(signum, _dropped)


def _dropped(signum: int, frame) -> None:
    """A signal once the outcome is settled: nothing to do. (A handler rather than ``SIG_IGN``: a signal that
    came just before the switch would otherwise be reported by Python as "ignored due to race condition".)"""


def exiting(status: int) -> None:
    """The command is over with ``status``: its outcome is settled, and a signal now, while the interpreter
    shuts down, ends the process at once with that same status (what is written and said stands), rather
    than with a traceback from a finalizer."""
    def end(signum: int, frame) -> None:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except Exception:  # noqa: BLE001 - interrupted inside a write of that stream: what it holds is lost
                pass
        os._exit(status)

    _Command.settled = True
    for signum in _answered():
        signal.signal(signum, end)


def _answered() -> list[int]:
    """The signals of :data:`DEFERRED` not ignored (one inherited ignored, by a shell's background job, stays so)."""
    return [signum for signum in DEFERRED if signal.getsignal(signum) is not signal.SIG_IGN]


def _ignore() -> None:
    for signum in DEFERRED:
        signal.signal(signum, signal.SIG_IGN)  # Python's shutdown resets its handlers to the default, not SIG_IGN


class _SendAgain:
    """``sys.unraisablehook``: the ``KeyboardInterrupt`` of a signal taken, dropped (see the module docstring), is
    sent again ``delay`` seconds later from a helper thread (sent from the hook itself, it would be taken at once,
    inside the hook, and dropped again); anything else goes to the ``previous`` hook."""

    delay = 0.05

    def __init__(self, previous):
        self.previous = previous

    def __call__(self, unraisable) -> None:
        if not (issubclass(unraisable.exc_type, KeyboardInterrupt) and RECEIVED):
            self.previous(unraisable)
            return
        again = threading.Timer(self.delay, os.kill, (os.getpid(), RECEIVED[-1]))
        again.daemon = True
        again.start()


@contextmanager
def signals_held() -> Iterator[Callable[[], None]]:
    """Hold SIGINT and SIGTERM while the block runs; yield the checkpoint that acts on the first one noted (see
    the module docstring), which the block's end calls too. Outside the main thread (where signals are not
    delivered) nothing is held."""
    with _holding() as (noted, act):
        def checkpoint() -> None:
            if noted:
                act(noted[0], None)
        yield checkpoint
    if noted:
        act(noted[0], None)


@contextmanager
def deferred(path: Path) -> Iterator[None]:
    """Hold SIGINT and SIGTERM while ``path`` is written; then act on the first one that came (see the module
    docstring)."""
    with _holding() as (noted, act):
        yield
    if noted:
        act(noted[0], path)


@contextmanager
def _holding() -> Iterator[tuple[list[int], Callable[[int, Path | None], None]]]:
    """The signals noted while the block runs, and ``act(signum, path)``: the handler before the block, raising
    :class:`WriteInterrupted` for a ``path`` written; the signal's default action where it had no handler."""
    noted: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield noted, lambda signum, path: None
        return
    def note(signum: int, frame) -> None:
        if not _Command.settled:
            noted.append(signum)

    previous: dict[int, Any] = {signum: signal.signal(signum, note) for signum in DEFERRED}

    def act(signum: int, path: Path | None) -> None:
        handler = previous[signum]
        if not callable(handler):
            for each, before in previous.items():
                signal.signal(each, before)
            signal.raise_signal(signum)  # SIG_DFL: the default action (SIG_IGN: nothing)
        elif path is not None:
            raise WriteInterrupted(signum, path)
        else:
            handler(signum, None)

    try:
        yield noted, act
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, _dropped if _Command.settled and callable(handler) else handler)
