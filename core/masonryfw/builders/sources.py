"""Where a model comes from: a netCDF file (a model or a result), a spec file, or a bundled case's name.

The one resolution of such a name, for the Python API and every command.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

from ..datasets import BUNDLED_NAMES, bundled_spec_path
from ..format.checks import check
from ..format.derived import DERIVED_VARIABLES, derive_geometry
from ..format.io import open_dataset
from ..format.model import checked_model, model_part
from ..readers.spec import read_spec
from ..runtime.errors import MasonryError, ModelError
from .kinds import build, files_read

if TYPE_CHECKING:  # annotations only
    import xarray as xr

#: The suffixes of a spec file (anything else that exists is read as a dataset file).
SPEC_SUFFIXES = (".toml",)


def is_spec(path: str | os.PathLike) -> bool:
    """Whether ``path`` names a spec file (by its suffix)."""
    return Path(path).suffix.lower() in SPEC_SUFFIXES


def _looks_like_a_path(text: str) -> bool:
    return os.sep in text or "/" in text or bool(Path(text).suffix)


def source_path(path_or_name: str | os.PathLike) -> Path:
    """The file ``path_or_name`` stands for: itself when it exists, else the spec of the bundled case of
    that name; raises :class:`ModelError` ("no such file", with the bundled cases when it is not a path)."""
    where = str(path_or_name)
    path = Path(path_or_name)
    if path.exists():
        return path
    if where in BUNDLED_NAMES:
        return bundled_spec_path(where)
    if _looks_like_a_path(where):
        raise ModelError(f"{where}: no such file")
    raise ModelError(f"{where}: no such file, and not a bundled case; bundled cases: {', '.join(BUNDLED_NAMES)}")


def input_files(*names: str | os.PathLike | None) -> list[Path]:
    """The user's files that ``names`` (paths, or bundled case names, as commands take them) stand for, and the
    files those read: a spec and its drawing, a dataset file. A command checks its output against them before
    its work (:func:`masonryfw.plugin_api.check_output_path`); what it reads later is guarded too (``inputs.guard_reads``)."""
    files = []
    for name in names:
        path = Path(name) if name is not None else None
        if path is None or not path.is_file():  # a bundled case's files are the package's
            continue
        files.append(path)
        if is_spec(path):
            files.extend(_drawing_of(path))
    return files


def _drawing_of(spec_path: Path) -> list[Path]:
    try:
        spec, _, base_dir = read_spec(spec_path)
    except MasonryError:  # a spec that cannot be read is refused, with its message, by the build
        return []
    return files_read(spec, base_dir)


def open_checked(path: str | os.PathLike) -> xr.Dataset:
    """A dataset file (a model, result, comparison or diagnosis) read and checked against its format; a
    :class:`ModelError` lists every problem. What draws or reports a file reads it so: a file can hold anything
    (NaN scores in a diagnosis ended a report deep in matplotlib)."""
    ds = open_dataset(path)
    problems = check(ds)
    if problems:
        raise ModelError(f"{path}: not a valid {ds.attrs.get('masonryfw_format', 'masonryfw')} dataset "
                         f"({len(problems)} problem(s))", problems)
    return ds


def open_model(path_or_name: str | os.PathLike, *, validate: bool = True) -> xr.Dataset:
    """A checked model from a netCDF file (a model or a result), a spec file (``.toml``) or a bundled case name.

    With ``validate=False`` the model is read but not checked (e.g. to list or
    draw a broken one); its derived geometry is still computed.
    """
    path = source_path(path_or_name)
    if is_spec(path):
        return build(path) if validate else derive_geometry(build(path, validate=False))
    ds = open_dataset(path)
    if validate:
        return checked_model(ds, str(path_or_name))
    model = model_part(ds)
    return derive_geometry(model.drop_vars([v for v in DERIVED_VARIABLES if v in model.variables]))
