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

from .errors import PluginError
from .options import parse_option_pairs


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
