"""``la``: rigid-block limit analysis of dry-joint walls under settlements (paper section 2.1).

Registration only; the method lives in :mod:`.assembly`, :mod:`.backends`,
:mod:`.postprocess` and :mod:`.solver`.
"""
from __future__ import annotations

import masonryfw as mf

from .solver import OPTIONS, solve

__version__ = "0.1.0"


@mf.hookimpl
def masonryfw_solvers():
    return [
        mf.Solver(
            name="la",
            summary="limit analysis: rigid blocks, no-tension dilatant Coulomb joints; alpha, mechanism, contact forces",
            solve=solve,
            version=__version__,
            options=OPTIONS,
        )
    ]
