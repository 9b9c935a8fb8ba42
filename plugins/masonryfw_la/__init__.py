"""``la``: rigid-block limit analysis of dry-joint walls under settlements (paper section 2.1).

Registration only (the solve is imported on first use); the method lives in
:mod:`.assembly`, :mod:`.backends`, :mod:`.ipm`, :mod:`.postprocess` and :mod:`.solver`.
"""
from __future__ import annotations

import masonryfw as mf

from .options import OPTIONS, VARIANTS


@mf.hookimpl
def masonryfw_solvers():
    return [
        mf.Solver(
            name="la",
            summary="limit analysis: rigid blocks, no-tension dilatant Coulomb joints; alpha, mechanism, contact forces",
            solve=mf.lazy("masonryfw_la.solver:solve"),
            options=OPTIONS,
            variants=VARIANTS,
            estimate=mf.lazy("masonryfw_la.estimate:estimate"),
        )
    ]
