"""The plugin contract: small, typed, documented hooks.

A plugin is a module (or object) with functions decorated by :data:`hookimpl`
whose names match the hooks below. Each hook returns a list of *records*
(:class:`Solver`, :class:`Comparator`, :class:`Plotter`) that the core looks up
by name (:mod:`masonryfw.contract.records`). A plugin is registered through the entry-point group ``masonryfw``::

    [project.entry-points.masonryfw]
    mysolver = "my_package"

Data contract (docs/format.md): a solve function receives a checked model with
its derived geometry and the options resolved by the core (defaults filled in,
every rule checked once, here); it returns a dataset holding only its primary
result variables. The core derives the comparable fields (relative motion at
the joints, joint states, crack indicator, macro-blocks) from
``block_displacement`` the same way for every solver, merges everything with the
model and stamps the provenance (``plugin``, ``solver``, ``solver_version``,
``solver_options``, ``wall_time_s``, hashes, a history line).
"""
from __future__ import annotations

from typing import Any

import pluggy

from .records import Comparator, Plotter, Solver

PROJECT = "masonryfw"
hookspec = pluggy.HookspecMarker(PROJECT)
#: The pluggy marker of a plugin's hook implementations (``@mfp.hookimpl``).
hookimpl = pluggy.HookimplMarker(PROJECT)


class MasonryfwSpec:
    """Hook specifications. Every hook takes no arguments and returns a list."""

    @hookspec
    def masonryfw_solvers(self) -> list[Solver]:
        """Return the solvers this plugin contributes."""

    @hookspec
    def masonryfw_comparators(self) -> list[Comparator]:
        """Return the comparators this plugin contributes."""

    @hookspec
    def masonryfw_plotters(self) -> list[Plotter]:
        """Return the plot kinds this plugin contributes."""

    @hookspec
    def masonryfw_commands(self) -> list[Any]:
        """Return extra ``click.Command`` objects added to the ``masonryfw`` CLI.

        For whole workflows a plugin owns (e.g. ``gallery``, ``export``); a command
        whose name is already taken is an error naming both plugins.
        """
