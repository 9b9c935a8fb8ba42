"""``la``: rigid-block limit analysis of dry-joint walls under settlements (paper section 2.1).

Registration only (the solve is imported on first use); the method lives in
:mod:`.assembly`, :mod:`.backends`, :mod:`.ipm`, :mod:`.postprocess`, :mod:`.limit` and :mod:`.solver`.

For other plugins (``la-incremental`` follows a wall through many limit states)::

    from masonryfw_la import Wall, limit_state, wall_scales
    wall = Wall.from_model(model)
    state = limit_state(wall, wall_scales(model, wall))  # alpha, mechanism, contact forces
"""
from __future__ import annotations

import lazy_loader

import masonryfw.plugin_api as mfp

from .options import OPTIONS, VARIANTS

# no __dir__: pluggy finds the hook implementations by dir(module)
__getattr__, _, __all__ = lazy_loader.attach(__name__, submod_attrs={
    "assembly": ["Scales", "Wall"],
    "backends": ["DeadLoadNotCarried", "LiveLoadUnbounded"],
    "limit": ["LimitState", "falling_motion", "limit_state", "wall_scales"],
})


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
            spaces=(2, 3),
        )
    ]
