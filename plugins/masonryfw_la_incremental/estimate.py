"""The ``la-incremental`` solve's time and peak memory, known before it starts (``Solver.estimate``).

Fitted to whole runs at the default step (docs/la.md, "Speed", 2026-11-28, the 2-core Intel Xeon VM, quiet):
an increment (two LPs, the contacts, the record) took 0.039 s on Test 12C (74 blocks), 0.086 s on Facade 3
(482) and 2.4 s on the 2,432-block running-bond wall, where the interior point's LPs take 1.2 s each: a
constant and a square fit the three (0.032, 0.12 and 2.43 s). The increments: the fastest point of a block
moves ``step`` unit heights in each at first, about 1.5 times as fast as the ground, and the steps grow while the
mechanism holds: 17 increments for Test 12C to 60 mm, 14 for the 2,432-block wall (this counts 17 and 17), 13 for
Facade 3 to 180 mm (this counts 50: a facade that settles as one macro-block grows its steps from the first).
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr

import masonryfw.plugin_api as mfp

SECONDS_PER_INCREMENT = 0.03  # a small wall's: the contacts, the record, two small LPs
SECONDS_PER_INCREMENT_AT_2432_BLOCKS = 2.4  # and what the LPs add, growing as blocks^2
INCREMENTS_PER_STEP_OF_GROUND = 0.7  # the ground's settlement over the step, times this: increments
BASE_MEMORY = 200 * 2**20  # the interpreter, numpy, scipy, xarray, HiGHS
MEMORY_PER_BLOCK = 40e3  # bytes: la's programme twice and the history's block motions


def estimate(model: xr.Dataset, options: Mapping[str, Any]) -> mfp.Estimate:
    from .solver import default_target  # the solver's own default, not a copy of it

    blocks = model.sizes["block"]
    masonry = mfp.masonry_blocks(model.block_role.values)
    _, _, ymin, ymax = mfp.block_bounds(model.node_x.values, model.node_y.values, model.block_node_count.values)
    unit_height = float(np.median((ymax - ymin)[masonry]))
    target = options["settlement"] or default_target(model)
    increments = max(1.0, INCREMENTS_PER_STEP_OF_GROUND * target / (options["step"] * unit_height))
    seconds = increments * (SECONDS_PER_INCREMENT + SECONDS_PER_INCREMENT_AT_2432_BLOCKS * (blocks / 2432) ** 2)
    return mfp.Estimate(seconds=seconds, memory=BASE_MEMORY + MEMORY_PER_BLOCK * blocks * (1 + increments / 100),
                        basis=f"{blocks:,} blocks, {mfp.count_text(increments)} increments to {target * 1e3:.3g} mm, as "
                              "fitted on the 2-core machine of docs/la.md (\"Speed\")",
                        advice="--option step=... larger than " + f"{options['step']:g}")
