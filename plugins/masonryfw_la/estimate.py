"""The ``la`` solve's time and peak memory, known before it starts (``Solver.estimate``).

Fits to the running-bond walls of docs/benchmarks.md, section "scale" (2026-11-25, 2-core
AMD EPYC, quiet machine): the interior point's time grows as blocks^1.4 (10,065 blocks:
5.9 s, 40,207 blocks: 40 s), its memory linearly (the CHOLMOD factor of ``G^T D G``); a
non-associative sequence costs about 45 associative solves (docs/la.md, "Speed").
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import xarray as xr

import masonryfw.plugin_api as mfp

SECONDS_AT_10K_BLOCKS = 5.9
TIME_EXPONENT = 1.4
NONASSOCIATIVE_FACTOR = 45.0
#: 3D models (Coulomb's cone by our interior point), fitted by the cones' points (interface vertices) to the
#: whole-process runs of docs/benchmarks.md, "la in 3D at scale" (2026-12-07, LMGC90 on the other core): the house
#: in units of 1, 1/2 and 1/3, the brick house and the brick terrace, 12,408 to 649,828 points, 2.8 to 146 s and
#: 0.28 to 2.67 GiB; the time of every one within 17 % of the fit, the memory within 2.3 % (by the blocks no
#: power law came within 40 %: a brick has more vertices). The base holds numba, which the cones' kernels need.
STARTUP_3D_SECONDS = 2.0
SECONDS_3D_AT_100K_POINTS = 12.5
TIME_EXPONENT_3D = 1.37
BASE_MEMORY_3D = 246 * 2**20
MEMORY_PER_POINT_3D = 4.0e3  # bytes
#: Non-associative friction in 3D: the sequence's time over the associative solve this estimate gives, 77x on the
#: corner building (1,212 points: 2.27 s) and 71x on the bundled house (12,408: 50.7 s), measured with the
#: regularised programmes (docs/benchmarks.md, "la: non-associative friction in 3D"): one factor for both.
NONASSOCIATIVE_3D_FACTOR = 74.0
BASE_MEMORY = 160 * 2**20  # the interpreter, numpy, scipy, xarray, cvxopt
MEMORY_PER_BLOCK = 25e3  # bytes


def estimate(model: xr.Dataset, options: Mapping[str, Any]) -> mfp.Estimate:
    blocks = model.sizes["block"]
    if mfp.space(model) == 3:
        points = model.sizes["interface_node"]
        solve = SECONDS_3D_AT_100K_POINTS * (points / 1e5) ** TIME_EXPONENT_3D
        if options["flow"] == "nonassociative":
            solve *= NONASSOCIATIVE_3D_FACTOR
        seconds = STARTUP_3D_SECONDS + solve
        return mfp.Estimate(seconds=seconds, memory=BASE_MEMORY_3D + MEMORY_PER_POINT_3D * points,
                            basis=f"{blocks:,} blocks with {points:,} interface vertices in 3D, as fitted on the "
                                  "buildings of docs/benchmarks.md on its 2-core machine (the cone; a pyramid of many "
                                  "sides takes longer)")
    seconds = SECONDS_AT_10K_BLOCKS * (blocks / 10_000) ** TIME_EXPONENT
    if options["flow"] == "nonassociative":
        seconds *= NONASSOCIATIVE_FACTOR
    return mfp.Estimate(seconds=seconds, memory=BASE_MEMORY + MEMORY_PER_BLOCK * blocks,
                       basis=f"{blocks:,} blocks, as fitted on the 2-core machine of docs/benchmarks.md")
