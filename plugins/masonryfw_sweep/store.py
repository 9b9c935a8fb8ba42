"""The content-addressed result store of a sweep.

Layout (every file written atomically: a temporary file renamed into place)::

    <store>/results/<key>.nc            a result (it holds its model, and the spec text in ``source_spec``)
    <store>/results/<key>.json          its record, written last: the commit mark

``key = sha256(model content hash, solver name, solver version, core version,
resolved options)`` (:func:`content_key`). Both versions carry a digest of the
code (the solver's package, the core that derives the comparable fields), so a
changed solver never gets an older result from the store. A result counts only when its record exists and
:meth:`Store.load_verified` re-derives the key from the record, matches the
result file's SHA-256 against the record and reopens the result, whose
provenance attributes must match too. A result file without its record (a
sweep killed between the two writes) or with a different hash is solved again
and replaced.
"""
from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Mapping
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

RESULTS = "results"


def content_key(model_sha256: str, solver: str, solver_version: str, core_version: str,
                options: Mapping[str, Any]) -> str:
    """Hex SHA-256 naming a result: same model content, solver, versions and options -> same key."""
    identity = {
        "model_sha256": model_sha256,
        "solver": solver,
        "solver_version": solver_version,
        "core_version": core_version,
        "solver_options": json.loads(mfp.options_json(options)),
    }
    return hashlib.sha256(json.dumps(identity, sort_keys=True).encode("utf-8")).hexdigest()


def model_hash(model: xr.Dataset) -> str:
    """The content hash of a model (what it holds, not how a file stores it)."""
    return mfp.content_sha256(model)


def _synced_text(text: str):
    """A writer of ``text`` that flushes it to disk (a record is the commit mark of its result)."""
    def write(temporary: Path) -> None:
        with open(temporary, "w", encoding="utf-8") as stream:
            stream.write(text)
            stream.flush()
            os.fsync(stream.fileno())
    return write


class Store:
    """A directory of results addressed by :func:`content_key`."""

    def __init__(self, root: str | os.PathLike):
        self.root = Path(root).resolve()

    def result_path(self, key: str) -> Path:
        return self.root / RESULTS / f"{key}.nc"

    def record_path(self, key: str) -> Path:
        return self.root / RESULTS / f"{key}.json"

    def committed(self) -> int:
        """How many results the store holds with their records (the commit marks)."""
        return sum(1 for _ in (self.root / RESULTS).glob("*.json"))

    def record(self, key: str) -> dict | None:
        """The record of ``key``, or None when absent or unreadable."""
        try:
            return json.loads(self.record_path(key).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return None

    def load_verified(self, key: str) -> xr.Dataset | None:
        """The stored result of ``key`` if its record, bytes and provenance all check out, else None."""
        record = self.record(key)
        if record is None or record.get("key") != key:
            return None
        try:
            derived = content_key(record["model_sha256"], record["solver"], record["solver_version"],
                                  record["core_version"], record["solver_options"])
        except (KeyError, TypeError):
            return None
        path = self.result_path(key)
        if derived != key or not path.is_file() or mfp.sha256_file(path) != record.get("result_sha256"):
            return None
        try:
            result = mf.open_dataset(path)
        except mf.MasonryError:
            return None
        attrs = result.attrs
        consistent = (
            attrs.get("model_sha256") == record["model_sha256"]
            and attrs.get("solver") == record["solver"]
            and str(attrs.get("solver_version")) == str(record["solver_version"])
            and str(attrs.get("core_version")) == str(record["core_version"])
            and attrs.get("solver_options") == mfp.options_json(record["solver_options"])
        )
        return result if consistent else None

    def put(self, key: str, model_sha256: str, result: xr.Dataset, provenance: Mapping[str, Any]) -> Path:
        """Store ``result``, then the record that commits it; return the result file."""
        (self.root / RESULTS).mkdir(parents=True, exist_ok=True)
        result_file = mf.save(result, self.result_path(key), command="masonryfw sweep: result of a sweep point")
        record = {
            "key": key,
            "model_sha256": model_sha256,
            "solver": result.attrs["solver"],
            "solver_version": str(result.attrs["solver_version"]),
            "core_version": str(result.attrs["core_version"]),
            "solver_options": json.loads(result.attrs["solver_options"]),
            "plugin": result.attrs.get("plugin", ""),
            "plugin_version": str(result.attrs.get("plugin_version", "")),
            "result": f"{RESULTS}/{result_file.name}",
            "result_sha256": mfp.sha256_file(result_file),
            "created": datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
            **provenance,
        }
        mfp.write_atomically({self.record_path(key): _synced_text(json.dumps(record, indent=2, sort_keys=True) + "\n")})
        return result_file
