"""The options of the ``jmm`` and ``jmm-limit`` solvers (cheap to import: registration needs only these)."""
from __future__ import annotations

import masonryfw.plugin_api as mfp

MESH_SIZE = mfp.Option("mesh_size", float, None, "largest cell side [m]; auto: half the unit height", above=0.0)
BETA = mfp.Option("beta", float, None, "interlocking beta; auto: tan(phi_bed) b / (2a) from the commonest unit",
                 at_least=0.0)
APEX_SHIFT = mfp.Option(
    "apex_shift", float, 1e-3,
    "regularisation: both Coulomb apexes moved this far into tension, as a fraction of gamma H; 0 = exact",
    at_least=0.0)

INCREMENTAL_OPTIONS = (
    mfp.Option("hypothesis", str, "plane_stress", "2D hypothesis", ("plane_stress", "plane_strain")),
    mfp.Option("element", str, "p2", "triangle: quadratic (p2, 3 quadrature points) or linear (p1)", ("p2", "p1")),
    MESH_SIZE,
    mfp.Option("shear_modulus", float, None, "G [Pa]; auto: from the model's block_young_modulus (else 511 MPa)",
              above=0.0),
    mfp.Option("poisson_ratio", float, None, "nu; auto: the model's block_poisson_ratio (else 0.2)",
              above=-1.0, below=0.5),
    BETA,
    mfp.Option("dilatancy", float, None, "dilatancy angle psi [deg]; auto: associated flow (psi = phi)",
              at_least=0.0, below=90.0),
    mfp.Option("vertex_stiffness", float, 1e-2,
              "fraction of D added to the tangent where it is rank-deficient (edges and vertices of the domain)",
              at_least=0.0),
    mfp.Option("settled_stiffness", float, 1e-2,
              "the same fraction once the active set has stopped changing (smaller: faster but less robust)",
              at_least=0.0),
    APEX_SHIFT,
    mfp.Option("tolerance", float, 1e-3,
              "Newton: ||free residual|| / ||gravity load|| (2-norms); tighter values move the reaction "
              "by < 1e-4 (docs/jmm.md)", above=0.0),
    mfp.Option("max_iterations", int, 30, "Newton iterations before a step is cut", above=0),
    mfp.Option("first_increment", float, 0.05,
              "first settlement increment, as a fraction of the elastic settlement that would unload the support",
              above=0.0),
    mfp.Option("max_increment", float, 1.0, "largest settlement increment, same unit as first_increment (with a "
              "target settlement: at least the target over 50)", above=0.0),
    mfp.Option("target_iterations", int, 3,
              "increments grow by 1.5 after steps of at most this many Newton iterations, halve after twice as many",
              above=0),
    mfp.Option("settlement", float, None, "target settlement [m]: the run stops there (or earlier, at the reaction "
              "plateau); auto: the model's settlement_target (a tunnel's S_max) if it has one, else 30 elastic "
              "unloading settlements",
              above=0.0),
    mfp.Option("max_steps", int, 200, "largest number of settlement (or load-factor) steps", above=0),
    mfp.Option("load_increment", float, 0.05,
              "without a moving support: the first increment of the live load's factor", above=0.0),
    mfp.Option("load_tolerance", float, 1e-3,
              "without a moving support: the run ends when a halved load increment falls below this", above=0.0),
    mfp.Option("plateau_slope", float, None, "plateau: |dR/ds| (or, without a moving support, the load factor's "
              "rate per unit displacement) below this fraction of the elastic (first step's) one ... "
              "(0: no plateau stop, run to the target settlement); auto: 0 when the target is the model's "
              "settlement_target, else 0.01", at_least=0.0),
    mfp.Option("plateau_steps", int, 3, "... over this many consecutive steps", above=0),
)

LIMIT_OPTIONS = (MESH_SIZE, BETA, APEX_SHIFT)
