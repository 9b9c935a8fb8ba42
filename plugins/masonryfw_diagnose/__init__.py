"""``diagnose``: from a crack survey (and a levelling) back to the settlement that caused it.

Registration only (cheap to import); the work lives in :mod:`.survey` (reading crack maps and levellings),
:mod:`.scenarios` (the ``[settlement]`` tables tried), :mod:`.scoring` (how well a mechanism explains a
survey's cracks), :mod:`.levelling` (the levelling as evidence, the free profile), :mod:`.diagnosis` (the
search and the ranking), :mod:`.parallel` (where the scenarios are solved), :mod:`.reranking` (the second
physics), :mod:`.features` (what a survey determines), :mod:`.dataset` (the ``diagnosis`` dataset and the
``--json`` contract), :mod:`.plotting` (the ``diagnosis`` plot) and :mod:`.commands` (the CLI command).
docs/diagnose.md says what the scores mean and where the method stops.

From Python::

    from masonryfw_diagnose import diagnose, read_cracks, wall_model
    diagnosis = diagnose(wall_model("facade-1"), read_cracks("cracks.geojson"))
    diagnosis.best.table  # a [settlement] table, best first: diagnosis.candidates
"""
from __future__ import annotations

import lazy_loader

import masonryfw.plugin_api as mfp

from .commands import COMMANDS

# no __dir__: pluggy finds the hook implementations by dir(module)
__getattr__, _, __all__ = lazy_loader.attach(__name__, submod_attrs={
    "dataset": ["to_dataset", "to_json"],
    "diagnosis": ["diagnose", "prepare", "search", "verify", "wall_model"],
    "parallel": ["local_processes"],
    "reranking": ["DEFAULT_BUDGET", "affordable", "rerank"],
    "scenarios": ["describe"],
    "survey": ["Survey", "read_cracks", "read_levelling"],
    "synthetic": ["visible_cracks"],
}, submodules=["synthetic"])

PLOTTER = mfp.Plotter(
    "diagnosis",
    "a settlement diagnosis: the surveyed cracks over the wall beside the best candidates' mechanisms and cracks, "
    "the scores of every candidate (and of the Gaussian troughs over their centre and width)",
    mfp.lazy("masonryfw_diagnose.plotting:draw_diagnosis"),
    options=(mfp.Option("amplification", float, None, "displacement amplification; auto: the largest motion drawn "
                       "as 8 % of the wall's size", above=0.0),),
)



@mfp.hookimpl
def masonryfw_commands():
    return list(COMMANDS)


@mfp.hookimpl
def masonryfw_plotters():
    return [PLOTTER]
