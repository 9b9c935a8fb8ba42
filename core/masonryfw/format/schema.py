"""Access to the machine-readable schemas in ``schemas/`` (installed as ``masonryfw.schemas``).

The schemas are the single source of variable names, dims, units, flag values
and bounds; validation and writers read them from here.
"""
from __future__ import annotations

import json
from functools import cache
from importlib import resources

from ..runtime.errors import ModelError

#: The data contract's version (docs/format.md).
FORMAT_VERSION = 2
#: The CF conventions every dataset follows (its ``Conventions`` attribute).
CONVENTIONS = "CF-1.11"


def format_header(kind: str) -> dict:
    """The global attributes that say what a dataset is: ``Conventions``, ``masonryfw_format`` (``kind``: model,
    result, comparison, sweep, diagnosis) and ``masonryfw_format_version``; every writer of a dataset starts
    from these."""
    return {"Conventions": CONVENTIONS, "masonryfw_format": kind, "masonryfw_format_version": FORMAT_VERSION}
#: Versions this code reads: older ones are upgraded in memory on reading (:func:`masonryfw.format.dofs.upgrade`).
READABLE_VERSIONS = (1, 2)
KINDS = ("model", "result", "comparison", "sweep", "diagnosis")
#: The schemas of a model and a result in 3D (``masonryfw_space = 3``; their ``masonryfw_format`` stays the kind).
KINDS_3D = {"model": "model3d", "result": "result3d"}


@cache
def load_schema(kind: str, version: int = FORMAT_VERSION) -> dict:
    """The schema of a dataset kind, with ``extends`` resolved (a result holds the model's variables)."""
    if kind not in KINDS and kind not in KINDS_3D.values():
        raise ModelError(f"unknown dataset kind {kind!r}; expected one of {', '.join(KINDS)}")
    path = resources.files("masonryfw.schemas").joinpath(f"{kind}-{version}.json")
    if not path.is_file():
        raise ModelError(f"unknown format version {version!r} for kind {kind!r}")
    schema = json.loads(path.read_text())
    base_kind = schema.get("extends")
    if base_kind:
        base = load_schema(base_kind, version)
        schema = dict(schema)
        schema["dimensions"] = {**base["dimensions"], **schema["dimensions"]}
        schema["fixed_sizes"] = {**base.get("fixed_sizes", {}), **schema.get("fixed_sizes", {})}
        # A result's copy of the model variables keeps their required flags.
        schema["variables"] = {**base["variables"], **schema["variables"]}
    return schema


def flags(variable: str) -> dict[str, int]:
    """``{meaning: value}`` of a flag variable, e.g. ``flags("interface_kind")["bed"] == 0``."""
    spec = load_schema("result")["variables"].get(variable)
    if spec is None or "flag_values" not in spec:
        raise KeyError(f"{variable!r} is not a flag variable of the format")
    return dict(zip(spec["flag_meanings"].split(), spec["flag_values"]))


def variable_attrs(variable: str, kind: str = "result") -> dict[str, object]:
    """CF attributes (units, long_name and flags where present) of a variable of the dataset ``kind``."""
    spec = load_schema(kind)["variables"][variable]
    attrs = {"units": spec["units"], "long_name": spec["long_name"]}
    if "flag_values" in spec:
        attrs["flag_values"] = list(spec["flag_values"])
        attrs["flag_meanings"] = spec["flag_meanings"]
    attrs.update(spec.get("attributes", {}))
    return attrs
