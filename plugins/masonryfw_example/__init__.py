"""Example plugin ``statics``: load resultants and support reactions. A template to copy.

A plugin is a module with ``@hookimpl`` functions returning records, registered
in its distribution's ``pyproject.toml``::

    [project.entry-points.masonryfw]
    example = "masonryfw_example"

The solve function gets a checked model with derived geometry and resolved
options, and returns a dataset holding only the variables it computed. The records name it with
``mfp.lazy``, so listing the plugins imports no solver code (nor NumPy or xarray).
"""
from __future__ import annotations

import masonryfw.plugin_api as mfp

#: The record, made once: every lookup returns the same object.
STATICS = mfp.Solver("statics", "load resultants and support dead reactions (no failure analysis)",
                    mfp.lazy("masonryfw_example.statics:solve_statics"), gallery=False)


@mfp.hookimpl
def masonryfw_solvers():
    """The records this plugin contributes (called once per lookup)."""
    return [STATICS]
