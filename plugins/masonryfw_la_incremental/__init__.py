"""``la-incremental``: how far the ground can move before the wall falls (rigid blocks, geometry updated).

Registration only (the solve is imported on first use). The method: :mod:`.stepping` (the increments),
:mod:`.configuration` (a moved wall as la's programme reads it), :mod:`.contacts` (contacts found
again), :mod:`.motion` (finite rigid motions), :mod:`.history` (the result dataset), :mod:`.solver`
(the solve function), :mod:`.estimate` (its time before it starts); docs/la.md, section "Displacement
capacity".
"""
from __future__ import annotations

import masonryfw.plugin_api as mfp

from .options import OPTIONS


@mfp.hookimpl
def masonryfw_solvers():
    return [
        mfp.Solver(
            name="la-incremental",
            summary="displacement capacity: la's mechanism at every increment on the moved geometry (finite "
                    "rotations, contacts found again) to collapse; settlement at collapse, reaction history",
            solve=mfp.lazy("masonryfw_la_incremental.solver:solve"),
            options=OPTIONS,
            gallery=False,
            estimate=mfp.lazy("masonryfw_la_incremental.estimate:estimate"),
            history=True,
        )
    ]
