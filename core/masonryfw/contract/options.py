"""Options: what a solver, comparator or plotter declares it accepts (:class:`Option`), and the one place
their values are parsed and checked (:func:`resolve_options`), for the command line and the Python API
alike."""
from __future__ import annotations

import difflib
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from ..runtime.errors import PluginError

_TRUE = {"1", "true", "yes", "on"}
_FALSE = {"0", "false", "no", "off"}
#: The word that asks for an option's automatic value (an option whose default is None).
AUTO = "auto"
_TYPES = (bool, int, float, str)


@dataclass(frozen=True)
class Option:
    """One option a solver, comparator or plotter accepts (``--option name=value``).

    ``type`` is the type of one value: bool, int, float or str. Rules, checked by
    the core once for every call (:func:`resolve_options`):

    - ``choices``: the value must be one of these;
    - ``above`` / ``at_least`` / ``below`` / ``at_most``: bounds (strict / inclusive);
    - ``default=None`` makes the option *automatic*: ``auto`` (or None) lets the
      plugin choose, and ``help`` must say how;
    - ``many=True``: a list of values (comma-separated on the command line), each
      obeying the rules; resolved as a tuple.
    """

    name: str
    type: type
    default: Any
    help: str = ""
    choices: tuple | None = None
    above: float | None = None
    at_least: float | None = None
    below: float | None = None
    at_most: float | None = None
    many: bool = False

    def __post_init__(self):
        if self.type not in _TYPES:
            raise PluginError(f"option {self.name!r}: type must be one of bool, int, float, str, not {self.type!r}")

    @property
    def auto(self) -> bool:
        """True when the option has an automatic value (its default is None)."""
        return self.default is None

    def rule(self) -> str:
        """The option's rules in words, e.g. ``> 0 and < 1`` (empty when there are none)."""
        parts = [f"{sign} {bound:g}" for sign, bound in (
            (">", self.above), (">=", self.at_least), ("<", self.below), ("<=", self.at_most)) if bound is not None]
        if self.choices is not None:
            parts.append("one of " + ", ".join(map(str, self.choices)))
        return " and ".join(parts)

    def usage(self) -> str:
        """``<float> > 0 and < 1 (default 1e-09)``: what the command line accepts."""
        kind = f"{self.type.__name__}[,{self.type.__name__}...]" if self.many else self.type.__name__
        rule = f" {self.rule()}" if self.rule() else ""
        shown = AUTO if self.auto else ",".join(map(str, self.default)) if self.many else repr(self.default)
        return f"<{kind}>{rule} (default {shown})"

    def parse(self, value: Any, owner: str = "") -> Any:
        """``value`` (a string from the command line or a Python value) converted and checked.

        Raises :class:`PluginError` naming the owner, the option, the value and the rule broken.
        """
        where = f"{owner}: option {self.name!r}" if owner else f"option {self.name!r}"
        if value is None or (isinstance(value, str) and value.strip().lower() == AUTO):
            if self.auto:
                return None
            raise PluginError(f"{where}: has no automatic value; give a {self.type.__name__}")
        if self.many:
            if isinstance(value, str):
                items = [v for v in value.split(",") if v.strip()]
            else:
                items = list(value) if isinstance(value, (list, tuple)) else [value]
            return tuple(self._one(item, where) for item in items)
        return self._one(value, where)

    def _one(self, value: Any, where: str) -> Any:
        parsed: Any
        try:
            if self.type is bool and isinstance(value, str):
                low = value.strip().lower()
                if low not in _TRUE | _FALSE:
                    raise ValueError(value)
                parsed = low in _TRUE
            elif self.type is int and isinstance(value, float) and not value.is_integer():
                raise ValueError(value)
            elif self.type is int and isinstance(value, str):
                number = float(value)
                if not number.is_integer():
                    raise ValueError(value)
                parsed = int(number)
            else:
                parsed = self.type(value.strip() if isinstance(value, str) and self.type is not str else value)
        except (TypeError, ValueError, OverflowError):
            raise PluginError(f"{where} = {value!r}: not a{'n' if self.type is int else ''} {self.type.__name__}") \
                from None
        if self.type in (int, float) and not math.isfinite(parsed):
            raise PluginError(f"{where} = {value!r}: must be finite")
        broken = self._broken_rule(parsed)
        if broken:
            raise PluginError(f"{where} = {parsed!r}: must be {broken}")
        return parsed

    def _broken_rule(self, value) -> str:
        if self.choices is not None and value not in self.choices:
            return "one of " + ", ".join(map(repr, self.choices))
        if self.type in (int, float) and any((
            self.above is not None and not value > self.above,
            self.at_least is not None and not value >= self.at_least,
            self.below is not None and not value < self.below,
            self.at_most is not None and not value <= self.at_most,
        )):
            return self.rule()
        return ""


def parse_option_pairs(pairs: Sequence[str]) -> dict[str, str]:
    """``["solver=highs", "tolerance=1e-9"]`` -> ``{"solver": "highs", "tolerance": "1e-9"}`` (CLI ``--option``)."""
    options = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key.strip():
            raise PluginError(f"--option {pair!r} is not KEY=VALUE")
        options[key.strip()] = value
    return options


def unknown_name_message(kind: str, name: str, valid: Sequence[str]) -> str:
    """``unknown option 'tolerence' (did you mean 'tolerance'?); valid: ...``: one message style for every lookup."""
    guess = difflib.get_close_matches(name, list(valid), n=1)
    hint = f" (did you mean {guess[0]!r}?)" if guess else ""
    return f"unknown {kind} {name!r}{hint}; valid {kind}s: {', '.join(sorted(valid)) or '(none)'}"


def resolve_options(owner: str, declared: Sequence[Option], given: Mapping[str, Any]) -> dict[str, Any]:
    """The options of one call: defaults overlaid by ``given``, every value parsed and checked.

    The only place option rules are applied; an unknown name, a value of the
    wrong type or outside its rules raises one :class:`PluginError` naming
    ``owner`` and the option.
    """
    by_name = {o.name: o for o in declared}
    for name in given:
        if name not in by_name:
            raise PluginError(f"{owner}: {unknown_name_message('option', name, list(by_name))}")
    resolved = {o.name: o.default for o in declared}
    resolved.update({name: by_name[name].parse(value, owner) for name, value in given.items()})
    return resolved
