"""``jmm`` and ``jmm-limit``: continuum FE with the Jointed Masonry Model (paper section 2.3).

Registration only (scikit-fem is imported when a solve starts); the method lives in
:mod:`.material` (the JMM return mapping), :mod:`.mesh`, :mod:`.fem`, :mod:`.problem`,
:mod:`.newton`, :mod:`.solver` (incremental settlement) and :mod:`.limit` (the static
limit LP on the same mesh). Both return a mechanism as block motions (the plateau's
displacement increment, the LP's dual velocities, fitted per block by
``masonryfw.rigid_fit``), from which the core derives ``crack_indicator`` and the
macro-blocks as for the discrete solvers; their plastic points (``qp_failure``) stay for
the plastic picture.
"""
from __future__ import annotations

import masonryfw.plugin_api as mfp

from .options import INCREMENTAL_OPTIONS, LIMIT_OPTIONS


@mfp.hookimpl
def masonryfw_solvers():
    return [
        mfp.Solver(
            name="jmm",
            summary="continuum FE, Jointed Masonry Model (anisotropic Coulomb + cut-off on bed/head planes): "
                    "gravity, then settlement steps (Newton) to the reaction plateau; plastic points",
            solve=mfp.lazy("masonryfw_jmm.solver:solve"),
            options=INCREMENTAL_OPTIONS,
            estimate=mfp.lazy("masonryfw_jmm.estimate:estimate"),
            history=True,
        ),
        mfp.Solver(
            name="jmm-limit",
            summary="the JMM continuum's collapse state directly: one static (lower-bound) limit LP on the mesh; "
                    "smallest moving-support reaction, alpha, plastic points",
            solve=mfp.lazy("masonryfw_jmm.limit:solve"),
            options=LIMIT_OPTIONS,
            estimate=mfp.lazy("masonryfw_jmm.estimate:estimate_limit"),
            gallery=False,
        ),
    ]
