"""``jmm``: continuum FE with the Jointed Masonry Model (paper section 2.3), settlement to failure.

Registration only (scikit-fem is imported when a solve starts); the method lives in :mod:`.material` (the JMM return mapping),
:mod:`.mesh`, :mod:`.fem`, :mod:`.problem`, :mod:`.newton`, :mod:`.solver` and
:mod:`.cracks`.
"""
from __future__ import annotations

import masonryfw as mf

from .options import OPTIONS

__version__ = "0.1.0"


@mf.hookimpl
def masonryfw_solvers():
    return [
        mf.Solver(
            name="jmm",
            summary="continuum FE, Jointed Masonry Model (anisotropic Coulomb + cut-off on bed/head planes): "
                    "settlement to the reaction plateau, plastic points",
            solve=mf.lazy("masonryfw_jmm.solver:solve"),
            version=__version__,
            options=OPTIONS,
        )
    ]
