"""``la``: rigid-block limit analysis of dry-joint walls under settlements (paper section 2.1).

Registration only (the solve is imported on first use); the method lives in
:mod:`.assembly`, :mod:`.backends`, :mod:`.ipm`, :mod:`.postprocess` and :mod:`.solver`.
"""
from __future__ import annotations

import masonryfw.plugin_api as mfp

from .options import OPTIONS, VARIANTS


@mfp.hookimpl
def masonryfw_solvers():
    return [
        mfp.Solver(
            name="la",
            summary="limit analysis: rigid blocks, no-tension dilatant Coulomb joints; alpha, mechanism, contact forces",
            solve=mfp.lazy("masonryfw_la.solver:solve"),
            options=OPTIONS,
            variants=VARIANTS,
            estimate=mfp.lazy("masonryfw_la.estimate:estimate"),
        )
    ]
