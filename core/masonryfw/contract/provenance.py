"""Provenance: the versions and code digests a result records, so that a stored result is never taken
for the answer of other code, and the canonical forms of options and inputs it is keyed on."""
from __future__ import annotations

import functools
import hashlib
import importlib.util
import json
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..format.io import content_sha256
from ..runtime.version import __version__
from .registry import Contribution, distribution, lookup

if TYPE_CHECKING:  # annotations only
    import xarray as xr


def plugin_version(item: Contribution) -> str:
    """The contributing distribution's version (the masonryfw version for a plugin registered by hand)."""
    dist = distribution(item.plugin)
    return dist[1] if dist else __version__


def _package_files(module_name: str) -> tuple[Path, list[Path]]:
    """The folder and the ``.py`` files of the top-level package of ``module_name`` (or of the module alone)."""
    top = module_name.split(".")[0]
    try:
        spec = importlib.util.find_spec(top)
    except (ImportError, ValueError):
        spec = None
    if spec is not None and spec.submodule_search_locations:
        root = Path(next(iter(spec.submodule_search_locations)))
        return root, sorted(root.rglob("*.py"))
    module = sys.modules.get(module_name) or sys.modules.get(top)
    origin = getattr(module, "__file__", None) or (spec.origin if spec is not None else None)
    if origin and Path(origin).is_file():
        return Path(origin).parent, [Path(origin)]
    return Path("."), []


@functools.cache
def code_digest(module_name: str) -> str:
    """First 12 hex digits of the SHA-256 of the code of the package holding ``module_name``.

    Every ``.py`` file of the package in sorted order, by its path relative to
    the package and its bytes: the same code gives the same digest wherever it
    is installed, and any edit changes it.
    """
    root, files = _package_files(module_name)
    digest = hashlib.sha256()
    for path in files:
        digest.update(path.relative_to(root).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:12]


def core_version() -> str:
    """masonryfw's version plus a digest of the core's code (what derives the comparable fields)."""
    return f"{__version__}+{code_digest(__name__)}"


def record_version(item: Contribution, function) -> str:
    """The recorded version of a record: its declared version (else its distribution's) plus its code's digest.

    Any change of the plugin's code changes it, so a store keyed on it never
    returns the result of older code.
    """
    base = item.record.version or plugin_version(item)
    return f"{base}+{code_digest(function.__module__)}"


def solver_version(name: str) -> str:
    """The version :func:`solve` records for the solver called ``name`` (see :func:`record_version`)."""
    item = lookup("solver", name)
    return record_version(item, item.record.solve)


def options_json(options: Mapping[str, Any]) -> str:
    """Resolved options as canonical JSON (sorted keys, tuples as lists): how results and stores record them."""
    return json.dumps(options, sort_keys=True, default=str)


def input_hash(ds: xr.Dataset) -> str:
    """The file's hash for a dataset read from a file, else the content hash."""
    return str(ds.encoding.get("sha256") or content_sha256(ds))
