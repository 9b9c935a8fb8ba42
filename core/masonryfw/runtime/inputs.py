"""A user's input files: what may be read, how much of it, and what a message about it may quote.

Every file a user names (a spec, a drawing, a survey, a levelling, a dataset) is read
through here. Only a regular file is read: a FIFO would block forever, a device
(``/dev/zero``) never ends. A text file is read whole only when it is under
:data:`TEXT_LIMIT`, and it must be UTF-8; a netCDF file given where text is expected
is named for what it is. Messages quote positions (line, column, row, feature), never
the contents of a file that may not be the user's (a spec key can point at any file).

Within a command (:func:`guard_reads`), every file read here is remembered by its device and inode, and no
output is written onto it, whatever path (link, relative, hard link) the output is given by
(:func:`was_read`, used by :mod:`masonryfw.format.io`): a drawn spec's ``-o wall.dxf`` replaced its own drawing.
"""
from __future__ import annotations

import os
import stat
from pathlib import Path

from .errors import MasonryError
from .resources import MEMORY_LIMIT_VARIABLE, available_memory, size_text

#: The largest text file (spec, CSV or GeoJSON drawing, survey) read whole: 64 MiB, 100 times the
#: largest drawing we know of (a 10,000-unit wall as GeoJSON is about 2 MiB).
TEXT_LIMIT = 64 * 2**20
#: Memory a reader needs per byte of a drawing file (measured: ezdxf's document of a 3.1 MB DXF of 19,200
#: polylines takes 53 MB, 17 times the file).
DRAWING_BYTES_FACTOR = 20
#: File signatures: netCDF-3 (classic, 64-bit offset, 64-bit data) and HDF5, which netCDF-4 files are.
NETCDF3_SIGNATURES = (b"CDF\x01", b"CDF\x02", b"CDF\x05")
HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
_KINDS = ((stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"), (stat.S_ISDIR, "a directory"))


#: The (device, inode) of every file read since :func:`guard_reads`; None outside a command (the Python API may
#: write over what it read, as a user's script asks).
_READ: set[tuple[int, int]] | None = None


def guard_reads() -> None:
    """A command begins: from now on the files read through this module are never written (:func:`was_read`)."""
    global _READ
    _READ = set()


def _note_read(info: os.stat_result) -> None:
    if _READ is not None:
        _READ.add((info.st_dev, info.st_ino))


def was_read(path: str | os.PathLike) -> bool:
    """Whether the file at ``path`` (through links) was read since :func:`guard_reads`."""
    if not _READ:
        return False
    try:
        info = os.stat(path)
    except OSError:
        return False
    return (info.st_dev, info.st_ino) in _READ


class InputError(MasonryError):
    """A user's file cannot be read as what it is given for; the message names the file and why."""


def file_kind(mode: int) -> str:
    """``"a FIFO (named pipe)"``, ``"a character device"``, ... or ``"a regular file"``."""
    return next((name for test, name in _KINDS if test(mode)), "a regular file")


def regular_file(path: str | os.PathLike, what: str, named: str | None = None) -> Path:
    """``path`` if it is (or links to) a regular file; else an :class:`InputError` saying what it is, about
    ``named`` (how the user gave it: a spec key) or the path."""
    file = Path(path)
    about = named or str(path)
    try:
        info = file.stat()
        mode = info.st_mode
    except FileNotFoundError:
        broken = " (a broken symbolic link)" if file.is_symlink() else ""
        raise InputError(f"{about}: no such file{broken}") from None
    except OSError as exc:
        raise InputError(f"{about}: cannot be read ({exc.strerror or exc})") from None
    if not stat.S_ISREG(mode):
        raise InputError(f"{about}: is {file_kind(mode)}, not a regular file; a {what} must be a file")
    _note_read(info)
    return file


def fits_in_memory(nbytes: float, what: str, advice: str = "") -> None:
    """Refuse work that would need more than the memory available (``MASONRYFW_MEMORY_LIMIT``)."""
    available = available_memory()
    if not nbytes <= available:
        needed = f"about {size_text(nbytes)}" if nbytes < float("inf") else "more than any machine has"
        raise InputError(f"{what} needs {needed} of memory and {size_text(available)} is available "
                         f"({MEMORY_LIMIT_VARIABLE} sets the limit){'; ' + advice if advice else ''}")


def is_netcdf(head: bytes) -> bool:
    """Whether ``head`` (a file's first bytes) is the start of a netCDF-3 or netCDF-4 (HDF5) file."""
    return head[:4] in NETCDF3_SIGNATURES or head[:8] == HDF5_SIGNATURE


def read_text(path: str | os.PathLike, what: str, limit: int = TEXT_LIMIT) -> str:
    """The UTF-8 text of the regular file ``path`` (a leading byte-order mark dropped), at most ``limit`` bytes.

    Refused with a message that names the file: not a regular file, too big, a netCDF
    file, not UTF-8 (the line and column of the first bad byte, not the text).
    """
    file = regular_file(path, what)
    try:
        with file.open("rb") as stream:
            data = stream.read(limit + 1)
    except OSError as exc:
        raise InputError(f"{path}: cannot be read ({exc.strerror or exc})") from None
    if len(data) > limit:
        raise InputError(f"{path}: over {size_text(limit)}, too big for a {what}")
    if is_netcdf(data[:8]):
        raise InputError(f"{path}: is a netCDF file (a model, result or sweep), not a {what}")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        column = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise InputError(f"{path}: is not UTF-8 text (byte 0x{data[exc.start]:02x} at line {line}, column {column}); "
                         f"a {what} must be saved as UTF-8") from None
