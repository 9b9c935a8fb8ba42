"""One writer at a time: an output file, or a sweep's store, is claimed before the work that writes it.

Two commands writing one file both used to succeed, and one result was silently lost. The
claim is an advisory ``flock`` on a hidden lock file beside the target
(``.<name>.lock``, holding the claimant's pid), taken when the output path is checked
(before any work) and released once the file is renamed into place, or when the process
ends. A second process is refused at once with a message naming the holder. Locks of a
process killed outright (SIGKILL) die with it: a stale lock file is not locked, and the
next claim reuses it. Where ``fcntl`` does not exist (Windows), nothing is locked.

A lock file is only ever ours: it is created new (``O_EXCL``), or an existing one is reused only when it is a
regular file of this user's, with no other link, holding nothing but a pid, opened without following a
symbolic link (``O_NOFOLLOW``) and without waiting on a FIFO (``O_NONBLOCK``). A symbolic link planted as
``.OUT.nc.lock`` used to be followed: the pid was written into the model it pointed at, or into any other
file, which was lost. Anything else in the lock's place is refused, named for what it is.
"""
from __future__ import annotations

import atexit
import os
import stat
from pathlib import Path

from .errors import MasonryError
from .inputs import file_kind

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
    :class:`BusyError` saying ``what`` is busy when another process holds it, and a :class:`MasonryError`
    when the lock's place holds something that is not a lock of ours. Claiming twice is one claim."""
    if fcntl is None or target in _HELD:
        return
    path = lock_file(target)
    while True:
        fd = _open_lock(path, what)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = _holder(fd)
            os.close(fd)
            raise BusyError(f"{what} is being written by another masonryfw process ({holder}); wait for it to "
                            "finish or choose another path") from None
        try:  # its last holder may have removed the lock file between our open and our lock: lock the new one
            current = os.stat(path, follow_symlinks=False).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            current = False
        if current:
            break
        os.close(fd)
    os.ftruncate(fd, 0)
    os.write(fd, f"{os.getpid()}\n".encode())
    _HELD[target] = fd


#: What a lock file of ours holds at most: a pid and a newline.
_LOCK_BYTES = 32
_OPEN = os.O_RDWR | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_NONBLOCK", 0)


def _open_lock(path: Path, what: str) -> int:
    """A descriptor of the lock file at ``path``: made new, or an earlier one of ours (module docstring)."""
    try:
        return os.open(path, _OPEN | os.O_CREAT | os.O_EXCL, 0o644)
    except FileExistsError:
        pass
    try:
        fd = os.open(path, _OPEN)
    except FileNotFoundError:  # its holder removed it since: make it anew
        return _open_lock(path, what)
    except OSError:  # ELOOP: a symbolic link; ENXIO: a FIFO nobody reads; ...
        raise MasonryError(_not_a_lock(path, what, _kind(path))) from None
    problem = _lock_problem(fd)
    if problem:
        os.close(fd)
        raise MasonryError(_not_a_lock(path, what, problem))
    return fd


def _lock_problem(fd: int) -> str | None:
    """Why the open file ``fd`` is not an earlier lock file of ours, or None."""
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode):
        return file_kind(info.st_mode)
    if info.st_uid != os.geteuid():
        return "another user's file"
    if info.st_nlink != 1:
        return f"a file with {info.st_nlink} names (a hard link)"
    if info.st_size > _LOCK_BYTES or not _holds_a_pid(fd):
        return "not a lock (it holds more than a pid)"
    return None


def _holds_a_pid(fd: int) -> bool:
    text = os.pread(fd, _LOCK_BYTES, 0).decode("ascii", "replace").strip()
    return text == "" or text.isdigit()


def _kind(path: Path) -> str:
    try:
        mode = os.stat(path, follow_symlinks=False).st_mode
    except OSError as exc:
        return f"unreadable ({exc.strerror})"
    return "a symbolic link" if stat.S_ISLNK(mode) else file_kind(mode)


def _not_a_lock(path: Path, what: str, problem: str) -> str:
    return (f"{what}: its lock file {path} is {problem}: refusing to use it or write into it; remove it if no "
            "masonryfw process is writing there")


def held_claims() -> set[Path]:
    """The outputs this process has claimed and not yet released (written or given up)."""
    return set(_HELD)


def release(target: Path) -> None:
    """Give up the claim on ``target`` (nothing when not held), removing its lock file (the one still ours)."""
    fd = _HELD.pop(target, None)
    if fd is None:
        return
    path = lock_file(target)
    try:
        if os.stat(path, follow_symlinks=False).st_ino == os.fstat(fd).st_ino:
            path.unlink()
    except FileNotFoundError:
        pass
    os.close(fd)


@atexit.register
def release_all() -> None:
    """Give up every claim of this process (the CLI does, at the end of each command, failed or not)."""
    for target in list(_HELD):
        release(target)
