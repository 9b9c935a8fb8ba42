"""Example plugin ``statics``: load resultants and support reactions. A template to copy.

A plugin is a module with ``@hookimpl`` functions returning records, registered
in its distribution's ``pyproject.toml``::

    [project.entry-points.masonryfw]
    example = "masonryfw_example"

The solve function gets a checked model with derived geometry and resolved
options, and returns a dataset holding only the variables it computed. The records name it with
``mf.lazy``, so listing the plugins imports no solver code (nor NumPy or xarray).
"""
from __future__ import annotations

import masonryfw as mf

#: The record, made once: every lookup returns the same object.
STATICS = mf.Solver("statics", "load resultants and support dead reactions (no failure analysis)",
                    mf.lazy("masonryfw_example.statics:solve_statics"), gallery=False)


@mf.hookimpl
def masonryfw_solvers():
    """The records this plugin contributes (called once per lookup)."""
    return [STATICS]
