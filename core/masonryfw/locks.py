"""One writer at a time: an output file, or a sweep's store, is claimed before the work that writes it.

Two commands writing one file both used to succeed, and one result was silently lost. The
claim is an advisory ``flock`` on a hidden lock file beside the target
(``.<name>.lock``, holding the claimant's pid), taken when the output path is checked
(before any work) and released once the file is renamed into place, or when the process
ends. A second process is refused at once with a message naming the holder. Locks of a
process killed outright (SIGKILL) die with it: a stale lock file is not locked, and the
next claim reuses it. Where ``fcntl`` does not exist (Windows), nothing is locked.
"""
from __future__ import annotations

import atexit
import os
from pathlib import Path

from .errors import MasonryError

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows
    fcntl = None  # type: ignore[assignment]

_HELD: dict[Path, int] = {}


class BusyError(MasonryError):
    """Another process holds the claim on a file or store; the message names it and the holder's pid."""


def lock_file(target: Path) -> Path:
    """The lock file of ``target``: ``.<name>.lock`` beside it."""
    return target.with_name(f".{target.name}.lock")


def _holder(fd: int) -> str:
    os.lseek(fd, 0, os.SEEK_SET)
    text = os.read(fd, 32).decode("ascii", "replace").strip()
    return f"pid {text}" if text.isdigit() else "another process"


def claim(target: Path, what: str) -> None:
    """Hold the lock of ``target`` (absolute) until :func:`release` or the end of the process; raise
    :class:`BusyError` saying ``what`` is busy when another process holds it. Claiming twice is one claim."""
    if fcntl is None or target in _HELD:
        return
    path = lock_file(target)
    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _holder(fd)
            os.close(fd)
            raise BusyError(f"{what} is being written by another masonryfw process ({holder}); wait for it to "
                            "finish or choose another path") from None
        try:  # its last holder may have removed the lock file between our open and our lock: lock the new one
            current = os.stat(path).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            current = False
        if current:
            break
        os.close(fd)
    os.ftruncate(fd, 0)
    os.write(fd, f"{os.getpid()}\n".encode())
    _HELD[target] = fd


def release(target: Path) -> None:
    """Give up the claim on ``target`` (nothing when not held), removing its lock file."""
    fd = _HELD.pop(target, None)
    if fd is None:
        return
    lock_file(target).unlink(missing_ok=True)
    os.close(fd)


@atexit.register
def release_all() -> None:
    """Give up every claim of this process (the CLI does, at the end of each command, failed or not)."""
    for target in list(_HELD):
        release(target)
