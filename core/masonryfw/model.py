"""A checked model, made once: opened from a file, a spec or a bundled case, validated, with derived geometry.

:func:`open_model` and :func:`masonryfw.build` return checked models;
:func:`masonryfw.solve` checks a model only if it was not checked before (or was
changed since: a checked model remembers the arrays it was checked with, so a
variable replaced by ``assign`` is noticed; an array edited in place is not).
"""
from __future__ import annotations

import os
from pathlib import Path

import xarray as xr

from .checks import check
from .dofs import upgrade
from .errors import ModelError
from .geometry import DERIVED_GEOMETRY_VARIABLES, derive_geometry
from .io import open_dataset
from .schema import load_schema

SPEC_SUFFIXES = (".toml",)
#: CF attributes describing a dataset that a model keeps when taken out of a result.
_DESCRIPTIVE_ATTRIBUTES = ("comment", "institution", "references", "source")
_CHECKED = "masonryfw_checked"


def model_part(ds: xr.Dataset) -> xr.Dataset:
    """The model a dataset holds: a model as is; for a result, its model variables and attributes.

    What a solver added (result variables, the solver's and the plugin's
    attributes) is dropped, so that solving a result anew attributes nothing of
    the old solve to the new solver. Encoding (source file, file hash) is kept.
    """
    ds = upgrade(ds)
    if ds.attrs.get("masonryfw_format") != "result":
        return ds
    schema = load_schema("model")
    keep_vars = set(schema["variables"]) | set(DERIVED_GEOMETRY_VARIABLES)
    keep_attrs = set(schema["global_attributes"]) | set(_DESCRIPTIVE_ATTRIBUTES)
    model = ds.drop_vars([name for name in ds.variables if name not in keep_vars])
    model.attrs = {k: v for k, v in ds.attrs.items() if k in keep_attrs}
    model.attrs["masonryfw_format"] = "model"
    model.encoding = dict(ds.encoding)
    return model


def _fingerprint(ds: xr.Dataset) -> tuple:
    """The arrays of the model's data variables (held, so that their identities cannot be reused).

    Index coordinates (``dof``) are left out: xarray hands out a new array for them on every access.
    """
    names = [*load_schema("model")["variables"], *DERIVED_GEOMETRY_VARIABLES]
    return tuple((name, ds.variables[name].data) for name in names if name in ds.variables and name not in ds.indexes)


def is_checked(ds: xr.Dataset) -> bool:
    """True when ``ds`` is a model checked by :func:`checked_model` and not changed since."""
    mark = ds.encoding.get(_CHECKED)
    now = _fingerprint(ds)
    return mark is not None and len(mark) == len(now) and all(
        a[0] == b[0] and a[1] is b[1] for a, b in zip(mark, now))


def checked_model(ds: xr.Dataset, where: str = "") -> xr.Dataset:
    """``ds`` (a model, or a result: its model) checked, with derived geometry; raises one ModelError listing every problem.

    Derived geometry stored in a file is never trusted: it is dropped and
    recomputed from the vertices. A model already checked is returned as it is.
    """
    if not isinstance(ds, xr.Dataset):
        raise TypeError(f"a model is an xarray.Dataset, not {type(ds).__name__}")
    kind = ds.attrs.get("masonryfw_format", "model")
    label = where or repr(ds.attrs.get("title", ""))
    if kind not in ("model", "result"):
        raise ModelError(f"{label}: a {kind} dataset (masonryfw_format = {kind!r}), not a model or a result")
    model = model_part(ds)
    if is_checked(model):
        return model
    stored = [v for v in DERIVED_GEOMETRY_VARIABLES if v in model.variables]
    model = model.drop_vars(stored)
    problems = check(model, kind="model")
    if problems:
        raise ModelError(f"model {label} is invalid ({len(problems)} problem(s))", problems)
    encoding = dict(model.encoding)
    model = derive_geometry(model)
    model.encoding = {**encoding, _CHECKED: _fingerprint(model)}
    return model


def _is_spec(path: Path) -> bool:
    return path.suffix.lower() in SPEC_SUFFIXES


def _looks_like_a_path(text: str) -> bool:
    return os.sep in text or "/" in text or bool(Path(text).suffix)


def open_model(path_or_name: str | os.PathLike, *, validate: bool = True) -> xr.Dataset:
    """A checked model from a netCDF file (a model or a result), a spec file (``.toml``) or a bundled case name.

    With ``validate=False`` the model is read but not checked (e.g. to list or
    draw a broken one); its derived geometry is still computed.
    """
    from .builder import build
    from .datasets import BUNDLED_NAMES, bundled_spec_path

    where = str(path_or_name)
    path = Path(path_or_name)
    if path.exists() and _is_spec(path):
        return build(path) if validate else derive_geometry(build(path, validate=False))
    if path.exists():
        ds = open_dataset(path)
    elif where in BUNDLED_NAMES:
        ds = build(bundled_spec_path(where), validate=False)
    elif _looks_like_a_path(where):
        raise ModelError(f"{where}: no such file")
    else:
        raise ModelError(f"{where}: no such file, and not a bundled case; bundled cases: {', '.join(BUNDLED_NAMES)}")
    if validate:
        return checked_model(ds, where)
    model = model_part(ds)
    return derive_geometry(model.drop_vars([v for v in DERIVED_GEOMETRY_VARIABLES if v in model.variables]))
