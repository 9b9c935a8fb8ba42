"""Reading specs: TOML files or text, typed access to their tables, the keys every wall shares, TOML output.

Shared by the parametric builder (:mod:`masonryfw.builders.parametric`) and drawn walls
(:mod:`masonryfw.builders.drawn`): ``[material]``, ``[loading]``, a support's
``motion``/``pivot``, ``length_unit``. A :class:`SpecError` names the key at fault.
"""
from __future__ import annotations

import difflib
import hashlib
import json
import math
import os
import re
from pathlib import Path

from ..runtime.errors import SpecError
from ..runtime.inputs import read_text
from .material import Material

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib

#: Metres per spec length unit (``length_unit``).
LENGTH_UNITS = {"m": 1.0, "cm": 1.0e-2, "mm": 1.0e-3}
_REQUIRED = object()


def read_spec(source) -> tuple[dict, str, Path | None]:
    """``(spec dict, TOML text, folder of the spec file or None)`` from a path, a Traversable, TOML text or a dict."""
    base_dir = None
    if isinstance(source, dict):
        return source, dump_toml(source), None
    if isinstance(source, os.PathLike) or hasattr(source, "read_text"):  # a path or a Traversable
        text = _read_text(source)
        base_dir = Path(os.fspath(source)).parent if isinstance(source, os.PathLike) else None
    elif isinstance(source, str):
        if os.path.exists(source):
            text = _read_text(source)
            base_dir = Path(source).parent
        elif "=" in source or "\n" in source:
            text = source
        else:
            raise SpecError(f"spec file {source!r} not found (and the text is not TOML)")
    else:
        raise SpecError(f"a spec is a path, TOML text or a dict, not {type(source).__name__}")
    try:
        return tomllib.loads(text), text, base_dir
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(f"spec is not valid TOML: {exc}") from None


def _read_text(path) -> str:
    if hasattr(path, "read_text") and not isinstance(path, os.PathLike):  # a Traversable of a bundled case
        return path.read_text(encoding="utf-8")
    return read_text(path, "spec (a TOML file)")


def is_finite_number(value) -> bool:
    """An int or float that is a finite float (an integer of 400 digits is not: it has no float)."""
    try:
        return isinstance(value, (int, float)) and math.isfinite(float(value))
    except OverflowError:
        return False


def shown(value, width: int = 60) -> str:
    """``repr(value)`` cut to ``width`` characters (a key holding a number of 400 digits is named, not printed)."""
    text = repr(value)
    return text if len(text) <= width else f"{text[:width - 12]}...({len(text)} characters)"


class SpecTable:
    """One table of a spec: typed access to its keys; unknown keys are rejected up front."""

    def __init__(self, table, path: str, allowed: tuple[str, ...], scale: float = 1.0):
        if not isinstance(table, dict):
            raise SpecError(f"spec key {path!r} must be a table, got {table!r}")
        self.table, self.path, self.scale = table, path, scale
        for name in table:
            if name not in allowed:
                guess = difflib.get_close_matches(name, allowed, n=1)
                hint = f" (did you mean {self.key(guess[0])!r}?)" if guess else f" (known keys: {', '.join(allowed)})"
                raise SpecError(f"unknown spec key {self.key(name)!r}{hint}")

    def key(self, name: str) -> str:
        return f"{self.path}.{name}" if self.path else name

    def has(self, name: str) -> bool:
        return name in self.table

    def raw(self, name: str, default=_REQUIRED):
        if name not in self.table:
            if default is _REQUIRED:
                raise SpecError(f"missing spec key {self.key(name)!r}")
            return default
        return self.table[name]

    def number(self, name: str, default=_REQUIRED, *, length=False, positive=False,
               minimum=None, below=None):
        value = self.raw(name, default)
        if value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise SpecError(f"spec key {self.key(name)!r} = {value!r}: must be a number")
        if not is_finite_number(value):
            raise SpecError(f"spec key {self.key(name)!r} = {shown(value)}: must be finite (at most 1.8e308)")
        if positive and value <= 0:
            raise SpecError(f"spec key {self.key(name)!r} = {value!r}: must be positive")
        if minimum is not None and value < minimum:
            raise SpecError(f"spec key {self.key(name)!r} = {value!r}: must be at least {minimum}")
        if below is not None and value >= below:
            raise SpecError(f"spec key {self.key(name)!r} = {value!r}: must be less than {below}")
        return float(value) * (self.scale if length else 1.0)

    def integer(self, name: str, default=_REQUIRED, *, minimum: int | None = None) -> int:
        value = self.raw(name, default)
        if isinstance(value, bool) or not isinstance(value, int):
            raise SpecError(f"spec key {self.key(name)!r} = {value!r}: must be a whole number")
        if minimum is not None and value < minimum:
            raise SpecError(f"spec key {self.key(name)!r} = {value!r}: must be at least {minimum}")
        return value

    def flag(self, name: str, default=_REQUIRED) -> bool:
        value = self.raw(name, default)
        if not isinstance(value, bool):
            raise SpecError(f"spec key {self.key(name)!r} = {value!r}: must be true or false")
        return value

    def choice(self, name: str, choices: tuple[str, ...], default=_REQUIRED) -> str:
        value = self.raw(name, default)
        if value not in choices:
            raise SpecError(
                f"spec key {self.key(name)!r} = {value!r}: must be one of {', '.join(map(repr, choices))}"
            )
        return value

    def text(self, name: str, default=_REQUIRED) -> str:
        value = self.raw(name, default)
        if not isinstance(value, str):
            raise SpecError(f"spec key {self.key(name)!r} = {value!r}: must be a string")
        return value

    def point(self, name: str) -> tuple[float, float]:
        value = self.raw(name)
        if (not isinstance(value, list) or len(value) != 2
                or any(isinstance(v, bool) or not is_finite_number(v) for v in value)):
            raise SpecError(f"spec key {self.key(name)!r} = {shown(value)}: must be a pair of finite numbers [x, y]")
        return float(value[0]) * self.scale, float(value[1]) * self.scale

    def sub(self, name: str, allowed: tuple[str, ...], default=_REQUIRED) -> SpecTable:
        return SpecTable(self.raw(name, default), self.key(name), allowed, self.scale)


_MATERIAL_KEYS = ("unit_weight", "friction_angle", "friction", "cohesion", "tensile_strength",
                  "young_modulus", "poisson_ratio")


def spec_relative(written: str, base_dir: Path | None) -> Path:
    """A file a spec names (its drawing): as written if absolute, else relative to ``base_dir`` (the spec file's
    folder; the working folder for a spec given as text or a dict)."""
    path = Path(written).expanduser()
    return path if path.is_absolute() or base_dir is None else base_dir / path


def open_spec(spec: dict, keys: tuple[str, ...], *, three_d: str | None = None) -> SpecTable:
    """The spec's top table (its ``keys`` the only ones allowed) with its length unit set, every builder's first
    step; ``three_d`` names what a kind that exists only in 3D is (e.g. ``"a [building]"``): its ``space`` must
    be 3 or left out."""
    top = SpecTable(spec, "", keys)
    top.scale = LENGTH_UNITS[top.choice("length_unit", tuple(LENGTH_UNITS), "m")]
    if three_d is not None and top.raw("space", 3) != 3:
        raise SpecError(f"spec key 'space' = {top.raw('space')!r}: {three_d} is 3D (space = 3, or leave it out)")
    return top


def refuse_ground_twice(top: SpecTable, how: str = "the profile makes the supports") -> None:
    """A wall stands on ``[supports.*]`` or on a ``[settlement]`` profile, not both (``how``: what the profile does)."""
    if top.has("settlement") and top.has("supports"):
        raise SpecError(f"spec tables 'settlement' and 'supports': give one of them ({how})")


def model_attributes(title: str, description: str, text: str, *, drawing: Path | None = None, notes=(),
                     **more: str) -> dict:
    """A built model's global attributes from its spec, every builder's last step: ``title``, ``source_spec`` (the
    spec's ``text``), ``comment`` (its ``description``, when it has one), ``source_drawing`` and its SHA-256 when
    it was drawn, ``laying_notes`` when laying it said something, and ``more``."""
    attrs = {"title": title, "source_spec": text, **more}
    if description:
        attrs["comment"] = description
    if drawing is not None:
        attrs["source_drawing"] = drawing.name
        attrs["source_drawing_sha256"] = hashlib.sha256(drawing.read_bytes()).hexdigest()
    if notes:
        attrs["laying_notes"] = "\n".join(notes)
    return attrs


def read_material(top: SpecTable) -> Material:
    """The ``[material]`` table."""
    material = top.sub("material", _MATERIAL_KEYS)
    if material.has("friction_angle") and material.has("friction"):
        raise SpecError("spec keys 'material.friction_angle' and 'material.friction': give one of them, not both")
    if material.has("friction"):
        friction = material.number("friction", minimum=0.0)
    elif not material.has("friction_angle"):
        raise SpecError("missing spec key 'material.friction_angle' (or 'material.friction')")
    else:
        friction = math.tan(math.radians(material.number("friction_angle", minimum=0.0, below=90.0)))
    return Material(
        unit_weight=material.number("unit_weight", positive=True),
        friction=friction,
        cohesion=material.number("cohesion", 0.0, minimum=0.0),
        tensile_strength=material.number("tensile_strength", 0.0, minimum=0.0),
        young_modulus=material.number("young_modulus", None, positive=True),
        poisson_ratio=material.number("poisson_ratio", None, minimum=-1.0, below=0.5),
    )


def read_loading(top: SpecTable, any_moving: bool) -> tuple[str, int]:
    """The ``[loading]`` table: ``(type, tilt direction)`` (direction 0 for settlement)."""
    loading = top.sub("loading", ("type", "direction"))
    kind = loading.choice("type", ("settlement", "tilt"))
    if kind == "tilt":
        direction = loading.raw("direction")
        if direction not in (1, -1) or isinstance(direction, bool):
            raise SpecError(f"spec key 'loading.direction' = {direction!r}: must be +1 (towards +x) or -1")
        return kind, int(direction)
    if loading.has("direction"):
        raise SpecError("spec key 'loading.direction' only applies to loading.type = 'tilt'")
    if not any_moving:
        raise SpecError("spec key 'loading.type' = 'settlement': needs at least one support with kind = 'moving'")
    return kind, 0


#: A translating support's direction unless its table gives one: straight down.
DOWN = (0.0, -1.0)
#: The keys of a support's motion (:func:`read_motion`), the same in every spec kind that has supports.
MOTION_KEYS = ("motion", "pivot", "rate", "direction")


def read_motion(entry: SpecTable, kind: str) -> tuple[str, tuple[float, float] | None, float, tuple[float, float]]:
    """``(motion, pivot, rate, direction)`` of a support table: ``none`` for a fixed support.

    ``rate`` (default 1) scales the support's motion per unit of the settlement
    parameter: a support at rate 0.5 settles half as fast as one at rate 1. A
    translating support moves along ``direction = [dx, dy]`` (default ``[0, -1]``,
    down; ``[1, 0]``: an arch's right springing moving out), taken as a unit vector.
    """
    if kind != "moving":
        for bad in ("motion", "pivot", "rate", "direction"):
            if entry.has(bad):
                raise SpecError(f"spec key {entry.key(bad)!r} only applies to kind = 'moving'")
        return "none", None, 0.0, DOWN
    motion = entry.choice("motion", ("translation", "rotation"), "translation")
    rate = entry.number("rate", 1.0, positive=True)
    if motion == "rotation":
        if entry.has("direction"):
            raise SpecError(f"spec key {entry.key('direction')!r} only applies to motion = 'translation'")
        return motion, entry.point("pivot"), rate, DOWN
    if entry.has("pivot"):
        raise SpecError(f"spec key {entry.key('pivot')!r} only applies to motion = 'rotation'")
    return motion, None, rate, read_direction(entry)


def read_direction(entry: SpecTable) -> tuple[float, float]:
    """A translating support's unit direction of motion (default down)."""
    if not entry.has("direction"):
        return DOWN
    value = entry.raw("direction")
    if (not isinstance(value, list) or len(value) != 2
            or any(isinstance(v, bool) or not is_finite_number(v) for v in value)
            or math.hypot(*value) == 0):
        raise SpecError(f"spec key {entry.key('direction')!r} = {value!r}: must be a non-zero pair [dx, dy] "
                        "(the direction the support moves in; [0, -1] down, [1, 0] to the right)")
    length = math.hypot(*value)
    return float(value[0]) / length, float(value[1]) / length


def check_pivot(entry: SpecTable, pivot: tuple[float, float] | None, centre_x: float, tol: float) -> None:
    """A rotating support's pivot must lie left or right of its centre (the rotation must move it down)."""
    if pivot is not None and abs(pivot[0] - centre_x) <= tol:
        raise SpecError(
            f"spec key {entry.key('pivot')!r} = {entry.raw('pivot')!r}: the pivot must lie left or "
            "right of the support's centre (a rotation about it must move the support down)"
        )


# --------------------------------------------------------------------------- TOML output

_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


def _toml_key(key: str) -> str:
    return key if _BARE_KEY.match(key) else json.dumps(key)


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    raise SpecError(f"cannot write a {type(value).__name__} value ({value!r}) to TOML")


def dump_toml(spec: dict, _prefix: str = "") -> str:
    """TOML text of a spec dict (scalars, arrays, tables, arrays of tables): the ``source_spec`` of a dict."""
    lines, tables = [], []
    for key, value in spec.items():
        if isinstance(value, dict):
            tables.append((key, value, False))
        elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            tables.append((key, value, True))
        else:
            lines.append(f"{_toml_key(key)} = {_toml_value(value)}")
    text = "\n".join(lines) + ("\n" if lines else "")
    for key, value, is_array in tables:
        name = _prefix + _toml_key(key)
        if is_array:
            for item in value:
                text += f"\n[[{name}]]\n" + dump_toml(item, name + ".")
        else:
            body = dump_toml(value, name + ".")
            has_scalars = not value or not all(isinstance(v, dict) for v in value.values())
            text += (f"\n[{name}]\n" if has_scalars else "") + body
    return text
