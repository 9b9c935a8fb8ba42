"""Sweep parameters: ``KEY=VALUES`` text, key-path checks, and the points of a grid or a zip.

A key is a dotted path into the builder spec (``supports.settling.start``,
``material.friction_angle``, ``openings.0.x`` for the first ``[[openings]]``
table) or ``option.<name>`` for a solver option. VALUES is a range
``start:stop:step`` (stop included when it lies on the grid within a relative
tolerance), a comma list ``18,21.8,30``, or a TOML array ``[[0.1, 0.0], [0.2, 0.0]]``
when the values themselves hold commas. Each list item is read as a TOML value
(``1`` an integer, ``0.5`` a float, ``true`` a boolean), falling back to the
text itself (``highs``).
"""
from __future__ import annotations

import copy
import difflib
import itertools
import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import masonryfw as mf
import masonryfw.plugin_api as mfp

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib

OPTION_PREFIX = "option."
#: A range's stop counts as reached when it is within this fraction of a step of a grid value.
RANGE_TOLERANCE = 1e-9
#: Range values are rounded to this many significant digits (0.3 + 3 * 0.1 -> 0.6, not 0.6000000000000001).
RANGE_DIGITS = 12

KeyPath = tuple  # of str (table keys) and int (array-of-tables indices)


@dataclass(frozen=True)
class Param:
    """One swept key and its values."""

    key: str
    values: tuple

    @property
    def is_option(self) -> bool:
        return self.key.startswith(OPTION_PREFIX)

    @property
    def option_name(self) -> str:
        return self.key[len(OPTION_PREFIX):]

    @property
    def path(self) -> KeyPath:
        """The spec path: table keys, with integer segments indexing arrays of tables."""
        return tuple(int(s) if s.isdigit() else s for s in self.key.split("."))

    @property
    def name(self) -> str:
        """The dimension / coordinate name: the key with every character outside ``[A-Za-z0-9_]`` as ``_``."""
        return re.sub(r"[^A-Za-z0-9_]", "_", self.key)


# --------------------------------------------------------------------------- text


def parse_param(text: str) -> Param:
    """``KEY=VALUES`` -> :class:`Param`; malformed text raises a SpecError quoting it."""
    key, sep, values = text.partition("=")
    key = key.strip()
    if not sep or not key:
        raise mf.SpecError(f"--param {text!r}: expected KEY=VALUES, e.g. material.friction_angle=18,21.8,30")
    if any(not segment for segment in key.split(".")):
        raise mf.SpecError(f"--param {key!r}: empty segment in the key path")
    return Param(key, parse_values(values.strip(), key))


def parse_values(text: str, key: str) -> tuple:
    """The values of ``--param KEY=text``: a range, a TOML array or a comma list."""
    if not text:
        raise mf.SpecError(f"--param {key}: no values given")
    if text.startswith("["):
        values = _toml_value(text)
        if not isinstance(values, list) or not values:
            raise mf.SpecError(f"--param {key}={text}: not a non-empty TOML array")
        return tuple(values)
    if ":" in text and "," not in text:
        return parse_range(text, key)
    tokens = [t.strip() for t in text.split(",")]
    if not all(tokens):
        raise mf.SpecError(f"--param {key}={text}: empty value in the list")
    return tuple(_scalar(t) for t in tokens)


def _toml_value(text: str) -> Any:
    try:
        return tomllib.loads(f"value = {text}")["value"]
    except tomllib.TOMLDecodeError:
        return None


def _scalar(token: str) -> Any:
    """A list item as the TOML value it spells, else as the plain text."""
    value = _toml_value(token)
    return token if value is None or isinstance(value, (dict, list)) else value


def parse_range(text: str, key: str) -> tuple:
    """``start:stop:step`` -> the values ``start + k step`` up to ``stop`` included (within tolerance)."""
    parts = [_scalar(p.strip()) for p in text.split(":")]
    if len(parts) != 3 or not all(isinstance(p, (int, float)) and not isinstance(p, bool) for p in parts):
        raise mf.SpecError(f"--param {key}={text}: a range is start:stop:step, three numbers")
    start, stop, step = parts
    if not all(math.isfinite(p) for p in parts):
        raise mf.SpecError(f"--param {key}={text}: range bounds and step must be finite")
    if step == 0 or (stop - start) / step < 0:
        raise mf.SpecError(f"--param {key}={text}: the step {step} does not lead from {start} to {stop}")
    count = math.floor((stop - start) / step + RANGE_TOLERANCE) + 1
    if all(isinstance(p, int) for p in parts):
        return tuple(start + step * k for k in range(count))
    return tuple(float(f"{start + step * k:.{RANGE_DIGITS}g}") for k in range(count))


# --------------------------------------------------------------------------- spec paths


def has_path(spec: Mapping, path: KeyPath) -> bool:
    """Whether ``path`` names an existing entry of ``spec``."""
    node: Any = spec
    for segment in path:
        if isinstance(node, dict) and segment in node:
            node = node[segment]
        elif isinstance(node, list) and isinstance(segment, int) and segment < len(node):
            node = node[segment]
        else:
            return False
    return True


def with_values(spec: Mapping, assignments: Iterable[tuple[KeyPath, Any]]) -> dict:
    """A deep copy of ``spec`` with every ``(path, value)`` set; missing tables are created."""
    out = copy.deepcopy(dict(spec))
    for path, value in assignments:
        node: Any = out
        for depth, segment in enumerate(path[:-1]):
            node = _child(node, segment, path[: depth + 1])
        _assign(node, path[-1], value, path)
    return out


def _dotted(path: KeyPath) -> str:
    return ".".join(map(str, path))


def _child(node, segment, where: KeyPath):
    if isinstance(node, list):
        if not isinstance(segment, int) or segment >= len(node):
            raise mf.SpecError(f"spec key {_dotted(where)!r}: no such entry ({len(node)} table(s) in the array)")
        return node[segment]
    if not isinstance(node, dict):
        raise mf.SpecError(f"spec key {_dotted(where)!r}: its parent is a value ({node!r}), not a table")
    return node.setdefault(segment, {})


def _assign(node, segment, value, path: KeyPath) -> None:
    if isinstance(node, list):
        _child(node, segment, path)  # raises for an index out of range
        node[segment] = value
    elif isinstance(node, dict):
        node[segment] = value
    else:
        raise mf.SpecError(f"spec key {_dotted(path)!r}: its parent is a value ({node!r}), not a table")


def check_spec_params(spec: Mapping, params: Sequence[Param]) -> None:
    """Raise a SpecError naming the first key that is neither in ``spec`` nor a builder key.

    A key already in the spec is accepted as is (a bad value is a failed point,
    not a bad sweep). A new key is tried with each of its values, every other
    swept key at its first value: it is rejected when every try fails with a
    SpecError naming what the key creates (the builder names the key at fault):
    an unknown key (``material.frcition``), a misspelt table
    (``supports.settlng.start``: its ``kind`` is missing), or
    ``material.friction`` next to ``material.friction_angle``.
    """
    spec_params = [p for p in params if not p.is_option]
    firsts = {p.key: (p.path, p.values[0]) for p in spec_params}
    for param in spec_params:
        if has_path(spec, param.path):
            continue
        others = [assignment for key, assignment in firsts.items() if key != param.key]
        errors = []
        for value in param.values:
            try:
                trial = with_values(spec, [*others, (param.path, value)])
            except mf.SpecError as exc:  # the path runs through a value: no value can fix that
                raise mf.SpecError(f"--param {param.key}: {exc}") from None
            try:
                mf.load_spec(trial)
            except mf.SpecError as exc:
                errors.append(exc)
                continue
            break
        else:
            new = _first_new(spec, param.path)
            created = re.compile(rf"'{re.escape(_dotted(new))}['.]")
            if all(created.search(str(error)) for error in errors):
                raise mf.SpecError(f"--param {param.key}: {_misspelt(spec, new) or errors[0]}")


def _misspelt(spec: Mapping, new: KeyPath) -> str:
    """``unknown key 'supports.settlng' (did you mean 'supports.settling'?)`` when the new key is close to
    an existing one beside it; else empty."""
    parent: Any = spec
    for segment in new[:-1]:
        parent = parent[segment]
    siblings = [str(k) for k in parent] if isinstance(parent, dict) else []
    guess = difflib.get_close_matches(str(new[-1]), siblings, n=1)
    if not guess:
        return ""
    return f"unknown key {_dotted(new)!r} (did you mean {_dotted((*new[:-1], guess[0]))!r}?)"


def _first_new(spec: Mapping, path: KeyPath) -> KeyPath:
    """The shortest prefix of ``path`` that ``spec`` does not have (what setting ``path`` creates)."""
    return next(path[:depth] for depth in range(1, len(path) + 1) if not has_path(spec, path[:depth]))


# --------------------------------------------------------------------------- options


def resolve_option_params(solver: mfp.Solver, params: Sequence[Param]) -> list[Param]:
    """``params`` with every ``option.<name>`` value parsed by the solver's declared option."""
    declared = {o.name: o for o in solver.options}
    out = []
    for param in params:
        if param.is_option:
            option = declared.get(param.option_name)
            if option is None:
                raise mf.PluginError(f"--param {param.key}: solver {solver.name!r}: "
                                     + mfp.unknown_name_message("option", param.option_name, list(declared)))
            owner = f"--param {param.key}: solver {solver.name!r}"
            param = replace(param, values=tuple(option.parse(v, owner) for v in param.values))
        out.append(param)
    return out


# --------------------------------------------------------------------------- points


def check_names(params: Sequence[Param]) -> None:
    """Keys must be distinct, and so must their dimension names."""
    seen: dict[str, str] = {}
    for param in params:
        if param.name in seen:
            raise mf.SpecError(
                f"--param {param.key}: "
                + ("given twice" if seen[param.name] == param.key else f"same dimension name as {seen[param.name]!r}")
            )
        seen[param.name] = param.key


def point_indices(params: Sequence[Param], zipped: bool) -> tuple[tuple[int, ...], list[tuple[int, ...]]]:
    """``(shape, per point the index into every param's values)``: cartesian product or zip."""
    if zipped:
        lengths = {p.key: len(p.values) for p in params}
        if len(set(lengths.values())) > 1:
            listed = ", ".join(f"{k} ({n})" for k, n in lengths.items())
            raise mf.SpecError(f"--zip needs the same number of values for every --param: {listed}")
        count = len(params[0].values)
        return (count,), [(i,) * len(params) for i in range(count)]
    shape = tuple(len(p.values) for p in params)
    return shape, list(itertools.product(*(range(n) for n in shape)))


def point_assignments(params: Sequence[Param], indices: tuple[int, ...]) -> tuple[list, dict]:
    """``(spec assignments [(path, value)], option overrides {name: value})`` of one point."""
    spec, options = [], {}
    for param, i in zip(params, indices):
        if param.is_option:
            options[param.option_name] = param.values[i]
        else:
            spec.append((param.path, param.values[i]))
    return spec, options
