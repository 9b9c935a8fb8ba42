"""The records this plugin registers: names, summaries and options only.

Importing this module is cheap (no matplotlib, scipy or meshio): the work is
imported on first use through :func:`masonryfw.contract.lazy`.
"""
from __future__ import annotations

import masonryfw as mf
import masonryfw.plugin_api as mfp

THRESHOLD_OPTION = mfp.Option(
    "threshold",
    float,
    mf.CRACK_THRESHOLD,
    "a joint is cracked where it moves more than this share of the largest joint motion (the core's crack "
    "threshold; states, indicator and macro-blocks are derived at it)",
    at_least=0.0,
    below=1.0,
)
AMPLIFICATION_OPTION = mfp.Option(
    "amplification", float, None, "displacement amplification; auto: the largest motion drawn as 10 % of the model size",
    above=0.0,
)
COMPARE_OPTIONS = (THRESHOLD_OPTION,)
#: The model plot draws interfaces by default up to this many blocks (beyond, their lines hide the blocks).
MODEL_INTERFACES_UP_TO = 400

COMPARATOR = mfp.Comparator(
    name="crack",
    summary="crack-pattern agreement: F1/Jaccard, overlap, Spearman, macro-block ARI, "
    "mechanism cosine, failure-locus distance",
    compare=mfp.lazy("masonryfw_compare.comparison:compare"),
    options=COMPARE_OPTIONS,
    spaces=(2, 3),
)


def _plotter(name: str, summary: str, options: tuple = (), table: bool = False,
             side_by_side: bool = False, module: str = "block_plots", spaces: tuple[int, ...] = (2,)) -> mfp.Plotter:
    return mfp.Plotter(name, summary, mfp.lazy(f"masonryfw_compare.{module}:draw_{name}"), options=options,
                      table=mfp.lazy(f"masonryfw_compare.{module}:{name}_table") if table else None,
                      side_by_side=side_by_side, spaces=spaces)


PLOTTERS = {
    plotter.name: plotter
    for plotter in (
        _plotter("model", "the model as built or imported: blocks by role, interfaces by kind, block numbers",
                 (mfp.Option("numbers", bool, False, "write every block's number at its centroid"),
                  mfp.Option("font_size", float, 5.0, "size of the block numbers [pt]", above=0.0),
                  mfp.Option("interfaces", str, "auto", "draw the interfaces coloured by kind: yes, no, or auto (a "
                             f"model of at most {MODEL_INTERFACES_UP_TO} blocks)", ("auto", "yes", "no"))),
                 spaces=(2, 3)),
        _plotter("mechanism", "amplified deformed wall, alpha and the reaction in the title, the dominant "
                 "macro-blocks numbered, cracks on the blocks' faces, the widest crack marked with the damage category "
                 "(3D: in axonometry, the cracked interfaces outlined)",
                 (AMPLIFICATION_OPTION, THRESHOLD_OPTION), spaces=(2, 3)),
        _plotter("cracks", "joints that open, slide or both, in colours; the widest crack marked with the damage "
                 "category", (THRESHOLD_OPTION,
                              mfp.Option("widths", bool, False, "draw each cracked joint as wide as its opening "
                                         "(amplified; its width in mm in the legend)")), spaces=(2, 3)),
        _plotter("forces", "contact forces (at collapse, or at the last record) as thrust segments",
                 (mfp.Option("scale", float, 1.0, "largest segment, in median interface lengths", above=0.0),)),
        _plotter("plastic", "plastic quadrature points over the mesh (continuum results)",
                 (mfp.Option("marker_size", float, 4.0, "marker area [pt^2]", above=0.0),)),
        _plotter("history", "reaction on the moving supports (or the damage) against settlement; several "
                 "incremental results overlaid, la results as their collapse reaction (1 - alpha) R0",
                 (mfp.Option("quantity", str, "reaction",
                            "reaction: on the moving supports; damage: the damage category and the widest crack",
                            ("reaction", "damage")),
                  mfp.Option("xscale", str, "linear", "settlement axis; log shows the first fraction of a millimetre "
                            "(where jmm's history lives) next to fdem's centimetres", ("linear", "log")),
                  mfp.Option("settlement_max", float, None, "zoom: the settlement axis ends here [mm]", above=0.0)),
                 table=True, module="history_plot", spaces=(2, 3)),
        _plotter("compare", "two or more results side by side with their scores",
                 (AMPLIFICATION_OPTION, THRESHOLD_OPTION), side_by_side=True, module="compare_plot", spaces=(2, 3)),
        _plotter("ltsm", "the engineers' stage 2 over a settlement profile: the trough under the wall (a building's "
                 "plan, its walls by category) and the LTSM interaction chart (deflection ratio against horizontal "
                 "strain, the category zones, the (worst) wall's sagging and hogging parts)", module="ltsm_plot",
                 spaces=(2, 3)),
    )
}
