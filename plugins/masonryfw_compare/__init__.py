"""``compare``: crack-pattern agreement scores, plots, the gallery and the VTK export.

Registration only (cheap to import: see :mod:`.records`); the work lives in
:mod:`.comparison` (the ``crack`` comparator), :mod:`.scores` (the score
functions), the plot kinds drawn through ``masonryfw.render`` (:mod:`.block_plots`,
:mod:`.history_plot`, :mod:`.compare_plot`, :mod:`.ltsm_plot`, their shared parts in
:mod:`.figure_parts`), :mod:`.gallery` and :mod:`.export`.
"""
from __future__ import annotations

import lazy_loader

import masonryfw.plugin_api as mfp

from .commands import COMMANDS
from .records import COMPARATOR, PLOTTERS

#: The Python API beyond ``masonryfw.compare`` / ``masonryfw.render``, imported on first access (lazy_loader, Scientific Python's SPEC 1)
#: so registering stays cheap.
# no __dir__: pluggy finds the hook implementations by dir(module)
__getattr__, _, __all__ = lazy_loader.attach(__name__, submod_attrs={
    "block_plots": ["drawable_kinds"],
    "export": ["export_vtk"],
    "report": ["report_html"],
})


@mfp.hookimpl
def masonryfw_comparators():
    return [COMPARATOR]


@mfp.hookimpl
def masonryfw_plotters():
    return list(PLOTTERS.values())


@mfp.hookimpl
def masonryfw_commands():
    return list(COMMANDS)
