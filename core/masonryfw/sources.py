"""Where a model comes from: a netCDF file (a model or a result), a spec file, or a bundled case's name.

The one resolution of such a name, for the Python API and every command.
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

from .builder import build
from .datasets import BUNDLED_NAMES, bundled_spec_path
from .errors import ModelError
from .geometry import DERIVED_GEOMETRY_VARIABLES, derive_geometry
from .io import open_dataset
from .model import checked_model, model_part

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
    return derive_geometry(model.drop_vars([v for v in DERIVED_GEOMETRY_VARIABLES if v in model.variables]))
