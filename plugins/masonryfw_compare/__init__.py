"""``compare``: crack-pattern agreement scores, plots, the gallery and the VTK export.

Registration only (cheap to import: see :mod:`.records`); the work lives in
:mod:`.comparison` (the ``crack`` comparator), :mod:`.scores` (the score
functions), the plot kinds drawn through ``masonryfw.render`` (:mod:`.block_plots`,
:mod:`.history_plot`, :mod:`.compare_plot`, :mod:`.ltsm_plot`, their shared parts in
:mod:`.figure_parts`), :mod:`.gallery` and :mod:`.export`.
"""
from __future__ import annotations

import importlib

import masonryfw as mf

from .commands import COMMANDS
from .records import COMPARATOR, PLOTTERS

#: The Python API beyond ``masonryfw.compare`` / ``masonryfw.render``, imported on first access (PEP 562)
#: so registering stays cheap.
_PUBLIC = {"export_vtk": "export"}
__all__ = sorted(_PUBLIC)


def __getattr__(name: str):
    if name in _PUBLIC:
        return getattr(importlib.import_module(f".{_PUBLIC[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


@mf.hookimpl
def masonryfw_comparators():
    return [COMPARATOR]


@mf.hookimpl
def masonryfw_plotters():
    return list(PLOTTERS.values())


@mf.hookimpl
def masonryfw_commands():
    return list(COMMANDS)
