"""The options and variants of the ``la`` solver (cheap to import: registration needs only these)."""
from __future__ import annotations

import masonryfw as mf

#: LP backends, highs first: the exact vertex, the gallery's reference.
BACKENDS = ("highs", "ipm", "clarabel", "osqp")
DEFAULT_BACKEND = "ipm"

OPTIONS = (
    mf.Option(
        "solver",
        str,
        DEFAULT_BACKEND,
        "LP backend: ipm (our interior point on the normal equations with CHOLMOD; fastest from "
        "~300 blocks, 2.2x Clarabel at 1,000 units, 3.5x at 10,000; tied mechanisms come out as their mean; "
        "infeasible problems go to clarabel), clarabel (conic interior point, fastest below ~300 "
        "blocks), highs (dual simplex, exact vertex; slow beyond a few hundred blocks), osqp "
        "(ADMM with proximal regularisation; slow, a cross-check)",
        BACKENDS,
    ),
    mf.Option("tolerance", float, 1e-9, "feasibility / optimality tolerance of the backend", above=0.0, below=1.0),
)

#: Every backend, run side by side by the gallery (their mechanisms may differ where the optimum is degenerate).
VARIANTS = tuple(mf.Variant(backend, {"solver": backend}) for backend in BACKENDS)
