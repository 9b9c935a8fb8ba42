"""The options and variants of the ``la`` solver (cheap to import: registration needs only these)."""
from __future__ import annotations

import masonryfw.plugin_api as mfp

#: LP backends, highs first: the exact vertex, the gallery's reference.
BACKENDS = ("highs", "ipm", "clarabel", "osqp")
DEFAULT_BACKEND = "ipm"

OPTIONS = (
    mfp.Option(
        "solver",
        str,
        None,
        "backend of the programme; auto: ipm. Coulomb's cone in 3D (a second-order cone programme) is solved by "
        "ipm (our interior point on the cones, Nesterov-Todd scaling: Clarabel takes 2.3x its time at 4,390 blocks, "
        "4.5x at 9,663) or "
        "clarabel. LP backends: ipm (our interior point on the normal equations with CHOLMOD; fastest from "
        "~300 blocks, 2.2x Clarabel at 1,000 units, 3.5x at 10,000; tied mechanisms come out as their mean; "
        "infeasible problems go to clarabel), clarabel (conic interior point, fastest below ~300 "
        "blocks), highs (dual simplex, exact vertex; slow beyond a few hundred blocks), osqp "
        "(ADMM with proximal regularisation; slow, a cross-check)",
        BACKENDS,
    ),
    mfp.Option("tolerance", float, 1e-9, "feasibility / optimality tolerance of the backend", above=0.0, below=1.0),
    mfp.Option("flow", str, "associative",
              "associative: a sliding joint opens by mu |slip| (dilatant, the paper's and ALMA's; an upper bound); "
              "nonassociative: joints slide without opening, by a sequence of LPs (in 3D of cone programmes, Coulomb's "
              "cone only) with the shear capacity of the previous normal forces (Gilbert, Casapulla & Ahmed 2006; "
              "docs/la.md)",
              ("associative", "nonassociative")),
    mfp.Option("flow_tolerance", float, 1e-6,
              "nonassociative: stop when alpha (relative) and every end's normal force (over the dead load) "
              "change by less than this between two LPs", above=0.0, below=1.0),
    mfp.Option("pyramid_sides", int, 0,
              "3D models: 0, Coulomb's friction cone itself (a second-order cone: exact, and faster than 8 sides, "
              "which are 4.2 % below it on the bundled house); N >= 3, a pyramid of N sides inscribed in "
              "the cone, its first side along the joint's horizontal tangent (exact along and across a wall's joints "
              "for a multiple of 4), solved by the option solver (docs/la.md, \"In 3D\"); at most 64 (32 sides are "
              "within 0.1 % of the cone)", at_least=0, at_most=64),
    mfp.Option("flow_iterations", int, 100, "nonassociative: the largest number of LPs", above=0),
    mfp.Option("flow_starts", int, 1,
              "nonassociative: 2 runs the sequence again from zero normal forces and says whether it ends at the "
              "same alpha (a fixed point need not be unique: docs/la.md; twice the time)", at_least=1, at_most=2),
    mfp.Option("flow_relaxation", float, 1.0,
              "nonassociative: share of the change of the normal forces taken from one LP to the next",
              above=0.0, at_most=1.0),
)

#: Every backend, run side by side by the gallery (their mechanisms may differ where the optimum is degenerate).
VARIANTS = tuple(mfp.Variant(backend, {"solver": backend}) for backend in BACKENDS)
