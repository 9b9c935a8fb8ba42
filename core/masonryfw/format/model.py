"""A checked model, made once: validated, with derived geometry.

:func:`masonryfw.open_model` and :func:`masonryfw.build` return checked models;
:func:`masonryfw.solve` checks a model only if it was not checked before or was
changed since: a checked model carries a digest of its variables' contents, so a
variable replaced by ``assign`` and an array edited in place are both noticed.
"""
from __future__ import annotations

import hashlib

import numpy as np
import xarray as xr

from ..runtime.errors import ModelError
from .checks import check
from .derived import DERIVED_VARIABLES, derive_geometry
from .dofs import upgrade
from .model3d import space
from .schema import load_schema

SPEC_SUFFIXES = (".toml",)
#: CF attributes describing a dataset that a model keeps when taken out of a result.
_DESCRIPTIVE_ATTRIBUTES = ("comment", "institution", "references", "source")
_CHECKED = "masonryfw_checked"
_MADE = "masonryfw_made_once"


def model_part(ds: xr.Dataset) -> xr.Dataset:
    """The model a dataset holds: a model as is; for a result, its model variables and attributes.

    What a solver added (result variables, the solver's and the plugin's
    attributes) is dropped, so that solving a result anew attributes nothing of
    the old solve to the new solver. Encoding (source file, file hash) is kept.
    """
    ds = upgrade(ds)
    if ds.attrs.get("masonryfw_format") != "result":
        return ds
    schema = load_schema("model3d" if space(ds) == 3 else "model")
    keep_vars = set(schema["variables"]) | set(DERIVED_VARIABLES)
    keep_attrs = set(schema["global_attributes"]) | set(_DESCRIPTIVE_ATTRIBUTES)
    model = ds.drop_vars([name for name in ds.variables if name not in keep_vars])
    model.attrs = {k: v for k, v in ds.attrs.items() if k in keep_attrs}
    model.attrs["masonryfw_format"] = "model"
    model.encoding = dict(ds.encoding)
    return model


def contents_digest(ds: xr.Dataset, names=None) -> str:
    """A digest of ``ds``'s global attributes and of its variables ``names`` (default: all; index
    coordinates left out, they are labels): names, dtypes, shapes and bytes, so that an array edited in
    place changes it. BLAKE2b, about 1 ms per MB: a few ms for a 10,000-block model, against the
    check's hundreds."""
    digest = hashlib.blake2b(repr(sorted(ds.attrs.items())).encode(), digest_size=16)
    for name in sorted(map(str, ds.variables)) if names is None else names:
        if name in ds.variables and name not in ds.indexes:
            data = np.ascontiguousarray(ds.variables[name].values)
            digest.update(f"{name}:{data.dtype.str}:{data.shape}".encode())
            digest.update(repr(data.tolist()).encode() if data.dtype.kind in "OUS" else data.tobytes())
    return digest.hexdigest()


def _fingerprint(ds: xr.Dataset) -> str:
    return contents_digest(ds, [*load_schema("model3d" if space(ds) == 3 else "model")["variables"],
                                *DERIVED_VARIABLES])


def checked_digest(ds: xr.Dataset) -> str | None:
    """The digest :func:`checked_model` recorded on a checked model (None on any other dataset)."""
    return ds.encoding.get(_CHECKED)


def is_checked(ds: xr.Dataset) -> bool:
    """True when ``ds`` is a model checked by :func:`checked_model` and not changed since (its variables'
    digest is the one recorded then)."""
    mark = ds.encoding.get(_CHECKED)
    return mark is not None and mark == _fingerprint(ds)


def made_once(model: xr.Dataset, name: str, make):
    """``make(model)`` once per checked ``model``'s contents: kept in its encoding under ``name`` with the digest
    :func:`checked_model` recorded, made again for a model changed (and checked) since. What a solver derives
    from a model for its estimate and again for its solve (fdem's scene), or the core's estimates."""
    digest = checked_digest(model)
    made = model.encoding.setdefault(_MADE, {})
    key = (name, digest)
    if digest is None or key not in made:
        made[key] = make(model)
    return made[key]


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
    stored = [v for v in DERIVED_VARIABLES if v in model.variables]
    model = model.drop_vars(stored)
    problems = check(model, kind="model")
    if problems:
        raise ModelError(f"model {label} is invalid ({len(problems)} problem(s))", problems)
    encoding = dict(model.encoding)
    model = derive_geometry(model)
    model.encoding = {**encoding, _CHECKED: _fingerprint(model)}
    return model
