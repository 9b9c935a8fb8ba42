"""The options of the ``jmm`` solver (cheap to import: registration needs only these)."""
from __future__ import annotations

import masonryfw as mf

OPTIONS = (
    mf.Option("method", str, "incremental",
              "incremental: gravity then settlement steps to the reaction plateau (Newton); limit: the collapse "
              "state directly, as one linear programme on the mesh (static lower bound, limit.py)",
              ("incremental", "limit")),
    mf.Option("hypothesis", str, "plane_stress", "2D hypothesis", ("plane_stress", "plane_strain")),
    mf.Option("element", str, "p2", "triangle: quadratic (p2, 3 quadrature points) or linear (p1)", ("p2", "p1")),
    mf.Option("mesh_size", float, 0.0, "largest cell side [m]; 0 = half the unit height"),
    mf.Option("shear_modulus", float, 0.0, "G [Pa]; 0 = from the model's block_young_modulus (else 511 MPa)"),
    mf.Option("poisson_ratio", float, 0.0, "nu; 0 = from the model's block_poisson_ratio (else 0.2)"),
    mf.Option("beta", float, -1.0, "interlocking beta; < 0 = tan(phi_bed) b / (2a) from the commonest unit"),
    mf.Option("dilatancy", float, -1.0, "dilatancy angle psi [deg]; < 0 = associated flow (psi = phi)"),
    mf.Option("vertex_stiffness", float, 1e-2,
              "fraction of D added to the tangent where it is rank-deficient (edges and vertices of the domain)"),
    mf.Option("settled_stiffness", float, 1e-2,
              "the same fraction once the active set has stopped changing (smaller: faster but less robust)"),
    mf.Option("apex_shift", float, 1e-3,
              "regularisation: both Coulomb apexes moved this far into tension, as a fraction of gamma H; 0 = exact"),
    mf.Option("tolerance", float, 1e-3,
              "Newton: ||free residual|| / ||gravity load|| (2-norms); tighter values move the reaction "
              "by < 1e-4 (docs/jmm.md)"),
    mf.Option("max_iterations", int, 30, "Newton iterations before a step is cut"),
    mf.Option("first_increment", float, 0.05,
              "first settlement increment, as a fraction of the elastic settlement that would unload the support"),
    mf.Option("max_increment", float, 1.0, "largest settlement increment, same unit as first_increment"),
    mf.Option("target_iterations", int, 3,
              "increments grow by 1.5 after steps of at most this many Newton iterations, halve after twice as many"),
    mf.Option("max_settlement", float, 0.0, "stop at this settlement [m]; 0 = 30 elastic unloading settlements"),
    mf.Option("max_steps", int, 200, "largest number of settlement steps"),
    mf.Option("plateau_slope", float, 0.01, "plateau: |dR/ds| below this fraction of the elastic slope ..."),
    mf.Option("plateau_steps", int, 3, "... over this many consecutive steps"),
)
