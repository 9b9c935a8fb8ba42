"""The options of the ``la-incremental`` solver (cheap to import: registration needs only these)."""
from __future__ import annotations

import masonryfw.plugin_api as mfp

#: la's LP backends (``masonryfw_la``'s solver option).
BACKENDS = ("ipm", "clarabel", "highs")

OPTIONS = (
    mfp.Option("settlement", float, None,
              "follow the wall to at most this settlement parameter t [m] (under a live load: this largest block "
              "translation); default the model's settlement_target, else a tenth of the wall's height", above=0.0),
    mfp.Option("step", float, 0.05,
              "the largest motion of any point of a block in one increment, as a share of the median unit height "
              "(adaptive: halved where blocks would overlap, grown up to 8 times while the mechanism stays the same; "
              "docs/la.md has the convergence study)",
              above=0.0, at_most=0.5),
    mfp.Option("gap", float, 0.005,
              "a vertex this close to a face of another block (as a share of the median unit height) touches it; "
              "joints that open wider lose their contact", above=0.0, at_most=0.1),
    mfp.Option("flow", str, "nonassociative",
              "nonassociative: joints slide without opening, against the shear capacity of the normal forces of "
              "the configuration's own associative state (la's first two non-associative LPs per increment); "
              "associative: la's dilatant joints, whose opening by mu |slip| lifts sliding blocks off their "
              "contacts after a few increments",
              ("nonassociative", "associative")),
    mfp.Option("increments", int, 5000, "the largest number of increments", above=0),
    mfp.Option("records", int, 0,
              "at least this many records over the target settlement (each increment at most target / records; 0: "
              "as the adaptive steps go); masonryfw capacity asks for 100, so that the settlement at which each "
              "damage category is reached is known to a hundredth of the run", at_least=0),
    mfp.Option("solver", str, "ipm", "la's LP backend for each increment (masonryfw solve --plugin la)", BACKENDS),
    mfp.Option("tolerance", float, 1e-9, "feasibility / optimality tolerance of the backend", above=0.0, below=1.0),
)
