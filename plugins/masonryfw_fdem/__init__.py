"""``fdem``: explicit discrete elements (rigid or CST-meshed blocks) under an imposed settlement (paper section 2.2).

Registration only (numba is imported when a solve starts); the method lives in :mod:`.scene` (model -> non-dimensional
arrays), :mod:`.kernels` (numba: contact detection, contact forces, time
stepping), :mod:`.simulation` (the gravity and settlement phases),
:mod:`.deformable` and :mod:`.deformable_simulation` (the CST mode),
:mod:`.postprocess` and :mod:`.solver`. See docs/fdem.md.
"""
from __future__ import annotations

import masonryfw.plugin_api as mfp

from .options import OPTIONS

__version__ = "0.1.0"


@mfp.hookimpl
def masonryfw_solvers():
    return [
        mfp.Solver(
            name="fdem",
            summary="explicit discrete elements: rigid or CST-meshed blocks, penalty Coulomb contacts, support "
            "moved slowly down; reaction history, final mechanism, energy balance",
            solve=mfp.lazy("masonryfw_fdem.solver:solve"),
            version=__version__,
            options=OPTIONS,
            estimate=mfp.lazy("masonryfw_fdem.estimate:estimate"),
            history=True,
            spaces=(2, 3),
        )
    ]
