"""netCDF read/write: whole-file reads, atomic CF-1.11 writes, history lines and hashes.

Reading loads the whole file into memory and closes it, so no handle stays
open and the file can be replaced afterwards. Writing goes to a temporary file
in the target's directory that replaces the target only once complete, so a
failed write never leaves a half-written or damaged file behind.

Every dataset is written in one normal form (:func:`cf_normalized`): the
schema's ``units``/``long_name`` on every format variable, flag variables as
``int8`` with ``flag_values`` of the same dtype, the CF geometry container for
block polygons. :func:`content_sha256` hashes that same normal form, so a
dataset and the file written from it share one content hash.
"""
from __future__ import annotations

import errno
import hashlib
import os
import secrets
import shutil
from collections.abc import Callable
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
import xarray as xr

from ..runtime import locks, signals
from ..runtime.errors import MasonryError, ModelError
from ..runtime.inputs import HDF5_SIGNATURE, file_kind, fits_in_memory, is_netcdf, regular_file, was_read
from ..runtime.version import __version__
from .derived import DERIVED_VARIABLES
from .dofs import upgrade
from .schema import CONVENTIONS, load_schema, variable_attrs

COMPRESSION = {"zlib": True, "complevel": 4, "shuffle": True}

_NODE_AXES = {"node_x": "X", "node_y": "Y"}
_GEOMETRY_VARIABLES = ("node_x", "node_y", "block_node_count")

_HASH_CHUNK = 1 << 20
#: A write that fails with less free space than this (bytes) in the target's folder failed on a full disk.
DISK_FULL = 1 << 20


# ---------------------------------------------------------------- hashing

def sha256_file(path: str | os.PathLike) -> str:
    """Hex SHA-256 of a file's bytes, read in 1 MiB chunks."""
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for chunk in iter(lambda: stream.read(_HASH_CHUNK), b""):
            digest.update(chunk)
    return digest.hexdigest()


def _feed(digest, *tokens: bytes) -> None:
    """Length-prefix every token so that no two token sequences hash alike."""
    for token in tokens:
        digest.update(len(token).to_bytes(8, "little"))
        digest.update(token)


def _strings_bytes(values) -> bytes:
    encoded = [(v if isinstance(v, bytes) else str(v).encode("utf-8")) for v in np.ravel(values)]
    return b"".join(len(e).to_bytes(8, "little") + e for e in encoded)


def _canonical_bytes(value) -> tuple[bytes, bytes]:
    """(type tag, bytes) of an attribute value, independent of its container (list, tuple,
    scalar, 1-element array) and integer/float width: files return attributes as arrays."""
    if isinstance(value, bytes):
        value = value.decode("utf-8", errors="replace")
    array = np.asarray(value)
    if array.dtype.kind in "USO":
        return b"str", _strings_bytes(array)
    if array.dtype.kind in "biu":
        return b"int", np.ascontiguousarray(array, dtype="<i8").tobytes()
    if array.dtype.kind == "f":
        # One NaN bit pattern: a NaN read back from a file may carry another payload.
        canonical = np.where(np.isnan(array), np.nan, array)
        return b"float", np.ascontiguousarray(canonical, dtype="<f8").tobytes()
    return b"repr", repr(value).encode("utf-8")


def _variable_bytes(values: np.ndarray) -> tuple[bytes, bytes]:
    """(dtype tag, bytes) of variable data; unlike attributes the exact dtype counts."""
    if values.dtype.kind in "USO":
        return b"str", _strings_bytes(values)
    little = values.dtype.newbyteorder("<")
    if values.dtype.kind == "f":
        values = np.where(np.isnan(values), np.nan, values).astype(values.dtype)
    return little.str.encode(), np.ascontiguousarray(values, dtype=little).tobytes()


def _feed_attrs(digest, attrs: dict) -> None:
    _feed(digest, str(len(attrs)).encode())
    for key in sorted(map(str, attrs)):
        _feed(digest, key.encode(), *_canonical_bytes(attrs[key]))


def content_sha256(ds: xr.Dataset) -> str:
    """Hex SHA-256 of what a dataset holds, not of how a file stores it.

    Hashes the normal form that :func:`save` writes (:func:`cf_normalized`):
    every variable's name, dims, shape, dtype and values, its attributes, and the
    global attributes except ``history``. Variables and attributes are taken in
    sorted order, so their order does not matter; the derived geometry is left
    out (it is recomputed from the vertices on every load). A dataset and the
    file :func:`save` writes from it therefore hash alike.
    """
    normal = cf_normalized(ds)
    digest = hashlib.sha256()
    _feed(digest, b"attributes")
    _feed_attrs(digest, {k: v for k, v in normal.attrs.items() if k != "history"})
    names = sorted(str(n) for n in normal.variables if n not in DERIVED_VARIABLES)
    for name in names:
        variable = normal.variables[name]
        dtype_tag, data = _variable_bytes(np.asarray(variable.values))
        _feed(digest, b"variable", name.encode(), " ".join(map(str, variable.dims)).encode())
        _feed(digest, np.asarray(variable.shape, dtype="<i8").tobytes(), dtype_tag, data)
        _feed_attrs(digest, variable.attrs)
    return digest.hexdigest()


# ---------------------------------------------------------------- reading

def _netcdf_problem(path: Path) -> str | None:
    """Why ``path`` cannot be a netCDF file, or None if it looks like one.

    Checks the signature: netCDF-3 files start with ``CDF``; netCDF-4 files are
    HDF5 files, whose signature sits at byte 0 or after a user block of 512,
    1024, 2048, ... bytes.
    """
    if not path.exists():
        return "no such file" + (" (broken symbolic link)" if path.is_symlink() else "")
    if path.is_dir():
        return "is a directory, not a netCDF file"
    if not path.is_file():
        return f"is {file_kind(path.stat().st_mode)}, not a regular file"
    size = path.stat().st_size
    if size == 0:
        return "is empty (0 bytes), not a netCDF file"
    with path.open("rb") as stream:
        head = stream.read(8)
        if is_netcdf(head):
            return None
        offset = 512
        while offset + len(HDF5_SIGNATURE) <= size:
            stream.seek(offset)
            if stream.read(len(HDF5_SIGNATURE)) == HDF5_SIGNATURE:
                return None
            offset *= 2
    return (
        f"is not a netCDF file (it starts with {head!r}; netCDF-3 files start with "
        f"b'CDF', netCDF-4 files with the HDF5 signature b'\\x89HDF')"
    )


def open_dataset(path: str | os.PathLike) -> xr.Dataset:
    """Read a masonryfw netCDF file (model, result, comparison or sweep) wholly into memory.

    The file is closed before returning. ``ds.encoding["source"]`` holds its
    absolute path and ``ds.encoding["sha256"]`` the hash of its bytes. Times are
    not decoded: the format holds plain SI numbers only. A file of an older
    format version is upgraded in memory (:func:`masonryfw.format.dofs.upgrade`).
    """
    file = Path(path)
    try:
        problem = _netcdf_problem(file)
        digest = None if problem else sha256_file(file)
    except OSError as exc:
        raise ModelError(f"{file}: cannot be read ({exc.strerror or exc})") from exc
    if problem:
        raise ModelError(f"{file}: {problem}")
    regular_file(file, "netCDF file")  # noted as read: never written over by the command (inputs.guard_reads)
    try:
        with xr.open_dataset(file, engine="netcdf4", decode_times=False, decode_timedelta=False) as src:
            _fits_in_memory(src, file)
            ds = src.load()
    except MasonryError:
        raise
    except Exception as exc:  # netCDF4/HDF5 raise OSError, RuntimeError, ValueError, ...
        raise ModelError(
            f"{file}: has a netCDF signature but cannot be read ({type(exc).__name__}: {exc}); "
            "is it truncated or damaged?"
        ) from exc
    ds = upgrade(ds)
    ds.encoding["source"] = str(file.resolve())
    ds.encoding["sha256"] = digest
    return ds


#: Memory to check a model and derive its geometry, per block (a model of a million blocks peaked at 2.9 GB).
CHECK_BYTES_PER_BLOCK = 3000


def _fits_in_memory(lazy: xr.Dataset, file: Path) -> None:
    """Refuse a file whose variables would not fit in memory once read, with the work of checking its blocks
    (before reading them: a file of a few MB can hold gigabytes of compressed zeros), naming the largest."""
    sizes = {name: v.size * (v.dtype.itemsize if v.dtype.kind != "O" else 64) for name, v in lazy.variables.items()}
    largest = max(sizes, key=sizes.__getitem__, default=None)
    if largest is not None:
        dims = ", ".join(f"{d} = {n:,}" for d, n in zip(lazy[largest].dims, lazy[largest].shape))
        blocks = lazy.sizes.get("block", 0)
        fits_in_memory(sum(sizes.values()) + CHECK_BYTES_PER_BLOCK * blocks,
                       f"{file}: reading it" + (f" and checking its {blocks:,} blocks" if blocks else ""),
                       f"its largest variable is {largest!r} ({dims}); is the file what it should be?")


# ---------------------------------------------------------------- writing

def add_history(ds: xr.Dataset, command: str) -> xr.Dataset:
    """A new dataset whose ``history`` has one more line: ``<UTC time> masonryfw <version>: <command>``."""
    stamp = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    line = f"{stamp} masonryfw {__version__}: {' '.join(str(command).split())}"
    previous = str(ds.attrs.get("history", "")).rstrip("\n")
    return ds.assign_attrs(history=f"{previous}\n{line}" if previous else line)


def _as_int8_flags(name: str, values: np.ndarray) -> np.ndarray:
    """``values`` as int8, refusing anything the cast would change (fractions, NaN, overflow)."""
    if values.dtype.kind in "iuf":
        with np.errstate(invalid="ignore"):
            exact = np.isfinite(values) & (values >= -128) & (values <= 127) & (values == np.trunc(values))
        if not exact.all():
            bad = np.flatnonzero(~exact.ravel())
            raise ModelError(
                f"variable {name!r}: flag values must be integers in -128..127; "
                f"found {values.ravel()[bad[0]].item()!r} at flat index {bad[0]} ({bad.size} such value(s))"
            )
    elif values.dtype.kind != "b":
        raise ModelError(f"variable {name!r}: flag values must be integers, not {values.dtype}")
    return values.astype(np.int8)


def cf_normalized(ds: xr.Dataset) -> xr.Dataset:
    """``ds`` in the form :func:`save` writes it (the caller's dataset is not changed).

    Adds what is missing: ``Conventions``; ``units``, ``long_name`` (and the
    schema's other attributes) on every format variable; ``axis`` on the node
    coordinates (CF 7.5 asks it of a geometry container's nodes); the ``block_geometry`` container when the dataset has polygons.
    Flag variables become ``int8`` with ``flag_values`` of the same dtype.
    """
    schema_variables = load_schema("result")["variables"]
    out = ds.copy(deep=False)
    out.attrs.setdefault("Conventions", CONVENTIONS)
    if all(v in out.variables for v in _GEOMETRY_VARIABLES) and "block_geometry" not in out.variables:
        out = out.assign(block_geometry=xr.Variable((), np.int32(0)))
    coords, data_vars = {}, {}  # replaced in one assignment each: every xarray assignment is a merge
    for name in [n for n in out.variables if n in schema_variables]:
        variable = out.variables[name]
        attrs = dict(variable.attrs)
        for key, value in variable_attrs(name).items():
            attrs.setdefault(key, value)
        if name in _NODE_AXES:
            attrs.setdefault("axis", _NODE_AXES[name])
        data = variable.data
        if "flag_values" in schema_variables[name]:
            data = _as_int8_flags(name, np.asarray(variable.values))
            attrs["flag_values"] = _as_int8_flags(f"{name}.flag_values", np.asarray(attrs["flag_values"]))
        replaced = xr.Variable(variable.dims, data, attrs, encoding=variable.encoding)
        (coords if name in out.coords else data_vars)[name] = replaced
    return out.assign_coords(coords).assign(data_vars)


def _netcdf_encoding(ds: xr.Dataset) -> dict[str, dict]:
    """zlib (level 4, shuffle) on every non-scalar numeric variable; no fill values on integers,
    which would make readers decode integers (flags, indices) to floats, nor on coordinates (CF 2.5.1)."""
    encoding = {}
    for name, variable in ds.variables.items():
        kind = variable.dtype.kind
        entry = dict(COMPRESSION) if kind in "biuf" and variable.ndim > 0 else {}
        if kind in "biu" or name in ds.coords:
            entry["_FillValue"] = None
        encoding[name] = entry
    return encoding


def _write_netcdf(ds: xr.Dataset, path: Path) -> None:
    """Write ``ds`` as netCDF-4, ignoring any encoding it carries from the file it came from."""
    fresh = ds.copy(deep=False)
    fresh.encoding = {}
    for variable in fresh.variables.values():
        variable.encoding = {}
    fresh.to_netcdf(path, mode="w", format="NETCDF4", engine="netcdf4", encoding=_netcdf_encoding(fresh))
    with open(path, "rb") as stream:
        os.fsync(stream.fileno())


def _same_file(a: Path, b: Path) -> bool:
    """Same file, through symbolic links, relative paths and hard links."""
    if a.resolve() == b.resolve():
        return True
    return a.exists() and b.exists() and os.path.samefile(a, b)


def _refusal(target: Path, ds: xr.Dataset, protect) -> str | None:
    """Why writing ``target`` would destroy an input, or None."""
    guarded = [(p, "a protected file") for p in protect]
    guarded.append((ds.encoding.get("source"), "the file this dataset was read from"))
    guarded.append((ds.attrs.get("source_file"), "the model file this result was computed from"))
    for candidate, what in guarded:
        if candidate and _same_file(target, Path(str(candidate))):
            return f"{what} ({candidate})"
    return None


def _read_refusal(target: Path) -> str | None:
    return f"{target.name}, a file this command read" if was_read(target) else None


def _writable_target(path: str | os.PathLike, refusal: str | None) -> Path:
    """The absolute target of a write, or a ModelError saying why it must not be written."""
    target = Path(path).resolve()
    if not target.parent.is_dir():
        raise ModelError(f"{path}: cannot write: directory {target.parent} does not exist")
    if target.is_dir():
        raise ModelError(f"{path}: cannot write: is a directory")
    if target.exists() and not target.is_file():  # a device or FIFO would be replaced by the rename
        raise ModelError(f"{path}: cannot write: is {file_kind(target.stat().st_mode)}, not a regular file; "
                         "results are written to regular files only")
    refusal = refusal or _read_refusal(target)
    if refusal:
        raise ModelError(f"{path}: refusing to overwrite {refusal}; write to another path")
    if not os.access(target.parent, os.W_OK | os.X_OK):
        raise ModelError(f"{path}: cannot write: no permission to create files in {target.parent}")
    locks.claim(target, str(path))
    return target


def check_output_path(path: str | os.PathLike, inputs=(), suffixes: tuple[str, ...] = ()) -> Path:
    """Raise (before any work) when ``path`` cannot be written; return it absolute.

    Refused: a missing or unwritable folder, a directory, one of ``inputs``
    (through links and relative paths), a suffix not among ``suffixes`` (when given).
    """
    suffix = Path(path).suffix.lower()
    if suffixes and suffix not in suffixes:
        raise MasonryError(f"{path}: unknown file type {suffix or '(none)'!r}; use one of {', '.join(suffixes)}")
    target = Path(path).resolve()
    refusal = next((f"the input {p}" for p in inputs if p and _same_file(target, Path(p))), None)
    return _writable_target(path, refusal)


def write_atomically(writes: dict[Path, Callable[[Path], object]], shown: str | os.PathLike | None = None) -> list[Path]:
    """Write a set of files as one: ``write(temporary)`` for each target (absolute, checked by
    :func:`check_output_path`), each temporary beside its target; once all are complete they are renamed onto
    their targets in order. On any failure nothing is renamed, no temporary is left and existing files are
    unchanged; Ctrl-C and SIGTERM wait until the set is written (:mod:`masonryfw.runtime.signals`)."""
    temporaries = {target: target.with_name(f".{target.name}.{secrets.token_hex(6)}.tmp{target.suffix}")
                   for target in writes}
    last = list(writes)[-1]
    read = next((f"{target}: refusing to overwrite {_read_refusal(target)}" for target in writes if was_read(target)),
                None)
    if read:  # read after its path was checked (a drawing named in a spec): the work is lost, the input is not
        for target in writes:
            locks.release(target)
        raise ModelError(f"{read}; write to another path")
    with signals.deferred(last):
        try:
            for target, write in writes.items():
                last = target
                write(temporaries[target])
                if target.exists():
                    shutil.copymode(target, temporaries[target])
            if locks.held_claims() <= set(writes):  # the command's last output: a signal from here on changes nothing
                signals.settle()
            for target, temporary in temporaries.items():
                os.replace(temporary, target)
                signals.WRITTEN.append(target)
        except BaseException as exc:
            for temporary in temporaries.values():
                temporary.unlink(missing_ok=True)
            if isinstance(exc, MasonryError) or not isinstance(exc, Exception):
                raise
            if len(writes) == 1:
                failed, unchanged = "", "any existing file is unchanged"
            else:
                failed, unchanged = f" {last.name}", f"none of its {len(writes)} files is written or changed"
            raise ModelError(f"{shown or last}: could not write{failed} ({write_failure(exc, last)}); "
                             f"{unchanged}") from exc
        finally:
            for target in writes:
                locks.release(target)
    return list(writes)


def write_failure(exc: BaseException, target: Path) -> str:
    """What went wrong in a failed write, in words: a full disk is said to be one (the netCDF library reports
    it as "Permission denied" or "NetCDF: HDF error")."""
    try:
        free = shutil.disk_usage(target.resolve().parent).free
    except OSError:
        free = None
    said = f"{type(exc).__name__}: {exc}"
    if getattr(exc, "errno", None) in (errno.ENOSPC, errno.EDQUOT) or (free is not None and free < DISK_FULL):
        return f"the disk is full: {free if free is not None else 0} bytes free in {target.resolve().parent}; {said}"
    return said


def save(
    ds: xr.Dataset,
    path: str | os.PathLike,
    *,
    command: str | None = None,
    protect=(),
) -> Path:
    """Write ``ds`` atomically as compressed CF-1.11 netCDF-4 and return the absolute path.

    The dataset is written in the normal form of :func:`cf_normalized` with one
    history line (``command``, or ``save``) appended. The file is written next
    to the target and renamed over it only when complete; on failure the target
    is left as it was. Refuses to write over any path in ``protect``, the file
    ``ds`` was read from, and the model file a result was computed from.
    """
    target = _writable_target(path, _refusal(Path(path).resolve(), ds, protect))
    try:
        prepared = add_history(cf_normalized(ds), command or "save")
    except BaseException:
        locks.release(target)
        raise
    return write_atomically({target: lambda temporary: _write_netcdf(prepared, temporary)}, path)[0]


#: The figure files ``save_figure`` writes.
FIGURE_FORMATS = (".png", ".svg", ".pdf")
#: Memory a pixel of a PNG figure takes while it is drawn and written (measured: 20 x 20 in at 1200 dpi, 576
#: million pixels, took 2.37 GB at the peak: 4.1 bytes a pixel, matplotlib's RGBA buffer and the encoder's rows).
BYTES_PER_PIXEL = 5
#: Matplotlib's Agg renderer draws images up to this many pixels a side.
MOST_PIXELS_A_SIDE = 2**16 - 1


def save_figure(figure, path: str | os.PathLike, *, protect=(), dpi: float | None = None, cropped: bool = True
                ) -> Path:
    """Write a matplotlib ``figure`` to ``path`` (.png, .svg or .pdf) atomically, cropped to what is drawn (no
    empty margins), or at exactly the figure's size (``cropped=False``: a size asked for); never onto
    ``protect``."""
    target = check_output_path(path, protect, FIGURE_FORMATS)
    suffix = target.suffix.lower()
    if suffix == ".png":
        width, height = figure.get_size_inches() * (dpi or figure.dpi)
        if max(width, height) > MOST_PIXELS_A_SIDE:
            raise ModelError(f"{path}: an image of {width:,.0f} x {height:,.0f} pixels; matplotlib draws at most "
                             f"{MOST_PIXELS_A_SIDE:,} a side: a smaller --size or --dpi, or .svg / .pdf")
        fits_in_memory(width * height * BYTES_PER_PIXEL, f"{path}: an image of {width:,.0f} x {height:,.0f} pixels "
                       f"({figure.get_size_inches()[0]:.3g} x {figure.get_size_inches()[1]:.3g} in at "
                       f"{dpi or figure.dpi:g} dpi)", "a smaller --size or --dpi, or .svg / .pdf (drawn, not pixels)")
    return write_atomically({
        target: lambda temporary: figure.savefig(temporary, format=suffix[1:], dpi=dpi or "figure",
                                                 bbox_inches="tight" if cropped else None, pad_inches=0.04)},
        path)[0]


def save_text(text: str, path: str | os.PathLike, *, protect=(), suffixes: tuple[str, ...] = ()) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically; never onto ``protect``; its suffix among ``suffixes``."""
    target = check_output_path(path, protect, suffixes)
    return write_atomically({target: lambda temporary: temporary.write_text(text, encoding="utf-8")}, path)[0]
