"""The ``fdem`` solve's time and peak memory, known before it starts (``Solver.estimate``).

The number of time steps to the target settlement is known from the controls (target /
(rate x dt)); the gravity phase lasts about ``controls.GRAVITY_TIME`` times sqrt(H / g) of simulated
time (H the masonry's height; a fixed share of the settlement steps was 5 % where it is 25-80 % for a
short target; a wall that does not come to rest runs longer, up to ``simulation.GRAVITY_TIME_LIMIT``, and the
run says so when it passes five times this estimate); a step costs about ``costs.STEP_SECONDS_PER_BLOCK`` a block on one thread (rigid polyhedra:
``costs.POLYHEDRA_SECONDS_PER_JOINT`` a joint; the 2-core
machine, ``costs.py`` says which day and host: the same VM ran 1.5x faster on an Intel Xeon host than on an
AMD EPYC one the same day), ``PARALLEL_EFFICIENCY`` of that less per added thread (the count the run will
most likely settle on, :mod:`.threads`), divided by the share of a core the run gets on a busy machine, times
``DEFORMABLE_FACTOR`` in the (serial) CST mode. A reaction plateau often stops the run earlier: the
estimate is the longest. The shared machine's speed itself varies from day to day: the same code ran the
1,035-block wall 1.65x faster on 2026-11-25 (same steps, same reactions), so no constant holds to 25 %
on every day; this one is the latest measurement.
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import xarray as xr

import masonryfw.plugin_api as mfp

from .controls import make_controls
from .costs import step_seconds
from .scene3d import scene_of

PARALLEL_EFFICIENCY = 0.55  # two threads 1.53x one on the 2,432-block wall (2026-11-27 evening; 1.59x on Facade 3)
BASE_MEMORY = 250 * 2**20
MEMORY_PER_BLOCK = 20e3


def estimate(model: xr.Dataset, options: Mapping[str, Any]) -> mfp.Estimate:
    scene = scene_of(model, options)
    controls = make_controls(scene, options)
    blocks = model.sizes["block"]
    steps = controls.gravity_steps_expected + (controls.target / (controls.rate * controls.dt) if controls.rate > 0 else 0.0)
    deformable = options["mode"] == "deformable"
    seconds = steps * step_seconds(blocks, scene.friction.size, deformable, polyhedra=scene.DOFS == 6)
    if not deformable:  # the CST mode is serial
        seconds /= (1 + PARALLEL_EFFICIENCY * (controls.threads.current - 1)) \
            * mfp.core_share(mfp.cores(), mfp.machine_load())
    return mfp.Estimate(seconds=seconds, memory=BASE_MEMORY + MEMORY_PER_BLOCK * blocks,
                       basis=f"{mfp.count_text(steps)} time steps, of {blocks:,} blocks, as fitted on the 2-core machine "
                             "of docs/benchmarks.md",
                       advice="fewer blocks (fdem's memory grows with the blocks and their contacts, not the options)")
