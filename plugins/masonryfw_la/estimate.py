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
#: 3D models (Coulomb's cone by Clarabel): the bundled house in units of 1, 1/2 and 1/3 of its own (docs/la.md,
#: "In 3D", 2026-11-28, quiet): 1,126 / 4,390 / 9,663 blocks solved in 2.4 / 24.4 / about 195 s, peak memory of the
#: whole process 0.18 / 0.40 / 0.78 GiB: time through the ends as blocks^2.04 (1.6 times the middle one), memory
#: linear.
SECONDS_3D_AT_1126_BLOCKS = 2.4
TIME_EXPONENT_3D = 2.04
MEMORY_PER_BLOCK_3D = 80e3  # bytes
BASE_MEMORY = 160 * 2**20  # the interpreter, numpy, scipy, xarray, cvxopt
MEMORY_PER_BLOCK = 25e3  # bytes


def estimate(model: xr.Dataset, options: Mapping[str, Any]) -> mfp.Estimate:
    blocks = model.sizes["block"]
    if mfp.space(model) == 3:
        return mfp.Estimate(seconds=SECONDS_3D_AT_1126_BLOCKS * (blocks / 1126) ** TIME_EXPONENT_3D,
                            memory=BASE_MEMORY + MEMORY_PER_BLOCK_3D * blocks,
                            basis=f"{blocks:,} blocks in 3D, as fitted on the bundled house on the 2-core machine of "
                                  "docs/la.md (the cone; a pyramid of many sides takes longer)")
    seconds = SECONDS_AT_10K_BLOCKS * (blocks / 10_000) ** TIME_EXPONENT
    if options["flow"] == "nonassociative":
        seconds *= NONASSOCIATIVE_FACTOR
    return mfp.Estimate(seconds=seconds, memory=BASE_MEMORY + MEMORY_PER_BLOCK * blocks,
                       basis=f"{blocks:,} blocks, as fitted on the 2-core machine of docs/benchmarks.md")
