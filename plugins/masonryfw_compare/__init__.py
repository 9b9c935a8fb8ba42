"""``compare``: crack-pattern agreement scores, plots, the gallery and the VTK export.

Registration only; the work lives in :mod:`.comparison` (the ``crack``
comparator), :mod:`.scores` (the score functions), :mod:`.plotting` (the plot
kinds, :func:`plot`, :func:`save_figure`), :mod:`.gallery` and :mod:`.export`.
"""
from __future__ import annotations

import masonryfw as mf

from .commands import COMMANDS
from .comparison import OPTIONS, compare
from .export import export_vtk
from .plotting import PLOTTERS, plot, save_figure

__version__ = mf.__version__
__all__ = ["compare", "export_vtk", "plot", "save_figure"]


@mf.hookimpl
def masonryfw_comparators():
    return [
        mf.Comparator(
            name="crack",
            summary="crack-pattern agreement: F1/Jaccard, overlap, Spearman, macro-block ARI, "
            "mechanism cosine, failure-locus distance",
            compare=compare,
            version=__version__,
            options=OPTIONS,
        )
    ]


@mf.hookimpl
def masonryfw_plotters():
    return list(PLOTTERS.values())


@mf.hookimpl
def masonryfw_commands():
    return list(COMMANDS)
