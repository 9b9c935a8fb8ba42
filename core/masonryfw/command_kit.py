"""What a plugin's command shares with the built-in ones (``masonryfw.cli``): the command line as typed (for
the history lines of what it writes), the ``--progress`` switch, the ``--option`` pairs and a positive length.

A plugin contributes a click command (hook ``masonryfw_commands``); with these its options read, check and
report as the built-in commands' do.
"""
from __future__ import annotations

import math
import shlex
import sys

import click

from .contract.options import parse_option_pairs
from .runtime.errors import PluginError


def command_line() -> str:
    """The command line as the ``masonryfw`` group recorded it, else this process's arguments."""
    obj = click.get_current_context().find_root().obj
    if isinstance(obj, dict) and obj.get("command_line"):
        return obj["command_line"]
    return shlex.join(["masonryfw", *sys.argv[1:]])


class Length(click.ParamType):
    """A positive, finite length in metres (``nan``, ``inf``, 0 and negatives are refused by name)."""

    name = "metres"

    def convert(self, value, param, ctx) -> float:
        try:
            number = float(value)
        except (TypeError, ValueError):
            self.fail(f"{value!r} is not a number", param, ctx)
        if not (math.isfinite(number) and number > 0):
            self.fail(f"{value!r} is not a positive, finite length", param, ctx)
        return number


#: ``type=LENGTH``: a positive, finite length in metres.
LENGTH = Length()


class Number(click.ParamType):
    """A finite number within bounds (``nan`` and ``inf`` refused by name, unlike click's FloatRange): ``above``
    (strictly) or ``at_least``, and ``at_most``; ``unit`` says what it is in."""

    def __init__(self, unit: str, *, above: float | None = None, at_least: float | None = None,
                 at_most: float | None = None):
        self.name, self.unit, self.above, self.at_least, self.at_most = unit, unit, above, at_least, at_most

    def convert(self, value, param, ctx) -> float:
        try:
            number = float(value)
        except (TypeError, ValueError):
            self.fail(f"{value!r} is not a number", param, ctx)
        wanted = [f"> {self.above:g}" if self.above is not None else "",
                  f">= {self.at_least:g}" if self.at_least is not None else "",
                  f"<= {self.at_most:g}" if self.at_most is not None else ""]
        if not (math.isfinite(number) and (self.above is None or number > self.above)
                and (self.at_least is None or number >= self.at_least)
                and (self.at_most is None or number <= self.at_most)):
            self.fail(f"{value!r}: a finite number {' and '.join(w for w in wanted if w)} ({self.unit})", param, ctx)
        return number


class Address(click.ParamType):
    """A dask scheduler's address: ``tcp://host:port`` (or ``tls://``, ``ws://``...), or ``host:port``."""

    name = "ADDRESS"
    SCHEMES = ("tcp", "tls", "ws", "wss", "inproc", "ucx")

    def convert(self, value, param, ctx) -> str:
        text = str(value).strip()
        scheme, _, rest = text.rpartition("://")
        host, _, port = rest.rpartition(":")
        if (scheme and scheme not in self.SCHEMES) or not host or not port.isdigit() or not 0 < int(port) < 65536:
            self.fail(f"{value!r} is not a scheduler's address: tcp://host:port, as the scheduler prints it "
                      f"(schemes: {', '.join(self.SCHEMES)})", param, ctx)
        return text if scheme else f"tcp://{text}"


#: ``type=ADDRESS``: a dask scheduler's address.
ADDRESS = Address()

#: Inches per unit a figure's ``--size`` may be given in.
SIZE_UNITS = {"in": 1.0, "cm": 1 / 2.54, "mm": 1 / 25.4}


class FigureSize(click.ParamType):
    """A figure's ``WIDTHxHEIGHT`` in inches, or with ``in``, ``cm`` or ``mm`` after it (``180x120mm``): each side
    positive, at most 100 inches."""

    name = "WxH[in|cm|mm]"

    def convert(self, value, param, ctx) -> tuple[float, float]:
        text = str(value).strip().lower()
        unit = next((u for u in SIZE_UNITS if text.endswith(u)), "in")
        sides = text.removesuffix(unit).split("x")
        try:
            width, height = (float(side) * SIZE_UNITS[unit] for side in sides)
        except (TypeError, ValueError):
            self.fail(f"{value!r} is not WIDTHxHEIGHT (inches, or with cm or mm after it: 180x120mm)", param, ctx)
        if not all(math.isfinite(side) and 0.5 <= side <= 100 for side in (width, height)):
            self.fail(f"{value!r}: each side between 0.5 and 100 inches (1.3 and 254 cm)", param, ctx)
        return width, height


#: ``@FIGURE``: ``--dpi`` and ``--size`` of a figure file.
def FIGURE(command):  # noqa: N802 - a decorator named as the other option sets
    command = click.option("--size", type=FigureSize(), default=None,
                           help="Figure size WIDTHxHEIGHT in inches, or 180x120mm / 18x12cm [default: the kind's].")(command)
    return click.option("--dpi", type=click.IntRange(50, 1200), default=200, show_default=True,
                        help="Resolution of a PNG (dots per inch of --size).")(command)

#: ``@PROGRESS``: ``--progress/--no-progress`` (``progress_bar`` draws what it asks for).
PROGRESS = click.option("--progress/--no-progress", default=None,
                        help="Progress on stderr [default: a bar on a terminal, a line a stage or 10 % elsewhere].")


def _option_pairs(ctx, param, value) -> dict[str, str]:
    try:
        return parse_option_pairs(value)
    except PluginError as exc:  # a malformed pair is a usage error (exit 2)
        raise click.BadParameter(str(exc)) from None


#: ``@OPTIONS``: ``--option KEY=VALUE`` (repeatable), parsed into a dict of strings.
OPTIONS = click.option("--option", "options", multiple=True, metavar="KEY=VALUE", callback=_option_pairs,
                       help="A plugin option (repeatable).")
