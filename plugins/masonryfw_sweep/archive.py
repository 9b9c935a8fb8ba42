"""``masonryfw archive``: a self-describing folder of a sweep, and its verification.

An archive has the store's layout (so it can serve as ``--store`` again: a
re-run of the sweep then solves nothing) plus what a reader needs to trust and
redo it::

    MANIFEST.json          SHA-256 and size of every other file; the command lines
    README.md              this layout, in words
    environment.json       Python, platform and every installed distribution's version
    sweep.nc               the sweep dataset, its result_path pointing into results/
    specs/sweep.toml       the spec the sweep started from
    specs/<model>.toml     the spec each model was built from
    models/<model>.nc      the models, rebuilt from their specs: the build is checked to reproduce
                           the content hash recorded when the point was solved
    results/<key>.nc/.json the results and their records, named by content key

The archive is assembled in a temporary folder beside the target and renamed
into place when complete, so a half-written archive never appears.
"""
from __future__ import annotations

import json
import os
import platform
import secrets
import shutil
import sys
from datetime import datetime, timezone
from importlib.metadata import distributions
from pathlib import Path

import numpy as np

import masonryfw as mf
import masonryfw.plugin_api as mfp

from .store import RESULTS, Store, model_hash
from .tasks import STATUS

MANIFEST = "MANIFEST.json"
ARCHIVE_FORMAT = "masonryfw-sweep-archive"
ARCHIVE_FORMAT_VERSION = 1
SWEEP_FILE = "sweep.nc"
SPECS = "specs"
MODELS = "models"

_README = """# masonryfw sweep archive

Written by `masonryfw archive`; check it with `masonryfw archive --verify <this folder>`.

| path | what |
|---|---|
| `MANIFEST.json` | SHA-256 and size of every other file, the sweep's and the archive's command lines |
| `environment.json` | Python, platform and the version of every installed distribution |
| `sweep.nc` | the sweep dataset (netCDF-4): swept keys as dimensions, scalar outputs, status and message per point; `result_path` points into `results/` |
| `specs/sweep.toml` | the spec the sweep started from (swept keys as in the sweep dataset) |
| `specs/<model>.toml` | the spec each model was built from |
| `models/<model>.nc` | the models, rebuilt from their specs and named by their content hash (checked equal to the hash recorded at solve time) |
| `results/<key>.nc` | the results, named by sha256(model hash, solver, solver version, options) |
| `results/<key>.json` | each result's record: the key's inputs and the result file's SHA-256 |

The folder is also a valid sweep store: `masonryfw sweep ... --store <this folder>`
reuses every result instead of solving it again.
"""


def _relative_files(root: Path) -> list[str]:
    """Every file under ``root`` except the manifest, as sorted POSIX paths relative to ``root``."""
    return sorted(p.relative_to(root).as_posix() for p in root.rglob("*") if p.is_file() and p.name != MANIFEST)


def environment() -> dict:
    """Python, platform and ``{distribution: version}`` of everything installed."""
    packages = {dist.metadata["Name"]: dist.version for dist in distributions() if dist.metadata["Name"]}
    return {
        "python": sys.version,
        "platform": platform.platform(),
        "packages": dict(sorted(packages.items(), key=lambda item: item[0].lower())),
    }


def _copy_point(key: str, source: Store, target: Path) -> tuple[str, str]:
    """Copy one verified result and its record into ``target``; return ``(model hash, spec text)``."""
    result = source.load_verified(key)
    if result is None:
        raise mf.ModelError(
            f"{source.result_path(key)}: missing, or does not match its record; re-run the sweep to restore it"
        )
    shutil.copy2(source.result_path(key), target / RESULTS)
    shutil.copy2(source.record_path(key), target / RESULTS)
    return str(result.attrs["model_sha256"]), str(result.attrs.get("source_spec", ""))


def _write_model(spec_text: str, model_sha256: str, target: Path) -> None:
    """Rebuild a model from its spec, check it is the model that was solved, write spec and model."""
    model = mf.build(spec_text)
    if model_hash(model) != model_sha256:
        raise mf.ModelError(
            f"the model {model_sha256} does not rebuild identically from its spec (content hash "
            f"{model_hash(model)}): the builder has changed since the sweep; re-run the sweep"
        )
    (target / SPECS / f"{model_sha256}.toml").write_text(spec_text, encoding="utf-8")
    mf.save(model, target / MODELS / f"{model_sha256}.nc", command="masonryfw archive: model rebuilt from its spec")


def _manifest(root: Path, sweep, sweep_file: Path, source: Store, command: str) -> dict:
    """The manifest of the archive being assembled in ``root``: provenance and every file's checksum."""
    return {
        "format": ARCHIVE_FORMAT,
        "format_version": ARCHIVE_FORMAT_VERSION,
        "created": datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "masonryfw_version": mf.__version__,
        "commands": {"sweep": sweep.attrs.get("sweep_command", ""), "archive": command},
        "source": {"sweep_file": str(sweep_file.resolve()), "sweep_file_sha256": mfp.sha256_file(sweep_file),
                   "store": str(source.root)},
        "files": {
            name: {"sha256": mfp.sha256_file(root / name), "bytes": (root / name).stat().st_size}
            for name in _relative_files(root)
        },
    }


def write_archive(target: str | os.PathLike, sweep_file: str | os.PathLike, command: str = "") -> Path:
    """Write the archive of the sweep in ``sweep_file`` to the new folder ``target``; return its path."""
    target = Path(target).resolve()
    if target.exists() and (not target.is_dir() or any(target.iterdir())):
        raise mf.ModelError(f"{target}: exists and is not an empty folder; archive into a new folder")
    if not target.exists():
        mfp.check_output_path(target)  # its folder exists and is writable
    sweep = mf.open_dataset(sweep_file)
    if sweep.attrs.get("masonryfw_format") != "sweep":
        raise mf.ModelError(f"{sweep_file}: not a sweep dataset (masonryfw_format is "
                            f"{sweep.attrs.get('masonryfw_format')!r}, not 'sweep')")
    ok = np.ravel(sweep.status.values) == STATUS["ok"]
    if not ok.any():
        raise mf.ModelError(f"{sweep_file}: no point succeeded; nothing to archive")
    # The store is where the results are: found through result_path, which survives moving the folder.
    first_result = Path(sweep_file).resolve().parent / str(np.ravel(sweep.result_path.values)[ok][0])
    source = Store(first_result.parent.parent)
    keys = list(dict.fromkeys(np.ravel(sweep.key.values)[ok].tolist()))

    temporary = target.with_name(f".{target.name}.{secrets.token_hex(6)}.tmp")
    try:
        for folder in (RESULTS, MODELS, SPECS):
            (temporary / folder).mkdir(parents=True)
        models = dict(_copy_point(key, source, temporary) for key in keys)
        for model_sha256, spec_text in models.items():
            _write_model(spec_text, model_sha256, temporary)
        (temporary / SPECS / "sweep.toml").write_text(sweep.attrs.get("source_spec", ""), encoding="utf-8")
        archived_paths = np.where(sweep.status.values == STATUS["ok"],
                                  np.char.add(np.char.add(f"{RESULTS}/", sweep.key.values.astype(str)), ".nc"), "")
        archived = sweep.assign(result_path=(sweep.result_path.dims, archived_paths, sweep.result_path.attrs))
        archived.attrs["sweep_store"] = "."
        mf.save(archived, temporary / SWEEP_FILE, command=command or "masonryfw archive")
        (temporary / "environment.json").write_text(json.dumps(environment(), indent=2) + "\n", encoding="utf-8")
        (temporary / "README.md").write_text(_README, encoding="utf-8")
        manifest = _manifest(temporary, sweep, Path(sweep_file), source, command)
        (temporary / MANIFEST).write_text(json.dumps(manifest, indent=2) + "\n", encoding="utf-8")
        if target.exists():
            target.rmdir()
        os.replace(temporary, target)
    finally:
        shutil.rmtree(temporary, ignore_errors=True)
    return target


def verify_archive(root: str | os.PathLike) -> list[str]:
    """Every mismatch in an archive, as ``path: what is wrong``; an empty list when it is intact.

    Checks each manifest entry's size and SHA-256, files the manifest does not
    list, that every netCDF file reopens, that every model's content hash is its
    name, and that every result matches its record (key, bytes, provenance).
    """
    root = Path(root)
    try:
        manifest = json.loads((root / MANIFEST).read_text(encoding="utf-8"))
        listed = dict(manifest["files"])
    except (OSError, ValueError, KeyError, TypeError) as exc:
        return [f"{MANIFEST}: missing or unreadable ({type(exc).__name__}: {exc})"]
    problems = []
    for name, entry in listed.items():
        path = root / name
        if not path.is_file():
            problems.append(f"{name}: missing")
        elif path.stat().st_size != entry.get("bytes"):
            problems.append(f"{name}: {path.stat().st_size} bytes, the manifest says {entry.get('bytes')}")
        elif mfp.sha256_file(path) != entry.get("sha256"):
            problems.append(f"{name}: SHA-256 differs from the manifest")
    problems += [f"{name}: not in the manifest" for name in _relative_files(root) if name not in listed]
    problems += _reopen_problems(root, [n for n in listed if n.endswith(".nc") and (root / n).is_file()])
    return problems


def _reopen_problems(root: Path, netcdf_files: list[str]) -> list[str]:
    store = Store(root)
    problems = []
    for name in netcdf_files:
        try:
            dataset = mf.open_dataset(root / name)
        except mf.MasonryError as exc:
            problems.append(f"{name}: does not reopen ({exc})")
            continue
        folder, stem = Path(name).parent.as_posix(), Path(name).stem
        if folder == MODELS and model_hash(dataset) != stem:
            problems.append(f"{name}: its content hash differs from its name")
        elif folder == RESULTS and store.load_verified(stem) is None:
            problems.append(f"{name}: does not match its record {RESULTS}/{stem}.json (key, SHA-256 or provenance)")
    return problems
