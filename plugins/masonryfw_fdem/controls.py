"""The controls of a run: the options made non-dimensional on a scene (stiffness, time step, target,
rates, tolerances), as the estimate and the solver both need them."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np

from .costs import call_steps, step_seconds
from .scene import Scene
from .scene3d import Scene3
from .threads import Threads


@dataclass(frozen=True)
class Controls:
    """Non-dimensional run parameters (resolved from the options by the solver)."""

    kn: float  # normal stiffness per unit contact length
    kt: float
    min_half: float  # half the shortest overlap that is a contact
    contact_damping: float
    dt: float
    dt_critical: float
    damping: float
    target: float  # settlement to reach (0: no settlement phase)
    rate: float  # settlement velocity
    ramp_time: float
    load_ramp: float  # duration of the smooth load ramp at the start
    gravity_time: float  # fixed duration of the gravity phase, 0: until at rest
    gravity_steps_expected: float  # about how many steps the gravity phase takes (:data:`GRAVITY_TIME`)
    rest_tolerance: float
    max_steps: int
    record_steps: int
    call_steps: int  # the most steps of one kernel call (Ctrl-C is taken between calls)
    threads: Threads  # the threads of each kernel call, chosen as the run goes
    buffer: float
    reclip: float  # 3D: the relative motion (a share of the smaller block's radius) after which a pair is clipped
    max_penetration: float
    min_cos: float
    sleep_speed: float  # 0: no sleeping
    sleep_steps: int
    wake_force: float
    plateau_tolerance: float
    plateau_window: float
    snapshots: tuple[float, ...]
    search: bool = False  # the load-factor search instead of a settlement
    search_first: float = 0.1
    search_limit: float = 10.0
    search_tolerance: float = 1e-3
    search_step_time: float = 1.0  # ramp to a trial multiplier
    search_trial_time: float = 20.0  # longest hold of one trial
    collapse_motion: float = 0.0  # block motion (centroid + rotation x radius) that makes a trial unstable


SEARCH_STEP_TIME = 1.0
SEARCH_TRIAL_TIME = 20.0
#: The gravity phase lasts about this many sqrt(masonry height / g) of simulated time (measured 0.23-0.68 on six
#: bundled walls, from the 0.6 m Test 12C to the 6 m tunnel facade).
GRAVITY_TIME = 0.4
#: ... and in 3D about this many (2026-12-03, the 3D defaults: 0.25, 0.33 and 0.64 on the corner building, the small
#: house of the building tests and the bundled house).
GRAVITY_TIME_3D = 0.45

#: The automatic contact stiffness: the base pressure penetrates this share of the unit height (2D: converged on the
#: walls, docs/fdem.md "Convergence") ...
PENETRATION_RATIO = 1e-4
#: ... and in 3D, eight times stiffer: at 1e-4 the bundled house's slender dry walls lean out of their plane (a
#: category 5 the settlement does not make); from 1.25e-5 to 6.25e-6 every wall keeps its category and the
#: building's widest crack moves under 10 % (docs/fdem.md, "In 3D").
PENETRATION_RATIO_3D = 1.25e-5

#: The reaction plateau that stops a run when the target is not the model's own (share of the dead reaction).
PLATEAU_TOLERANCE = 0.005


def penetration_ratio(scene: Scene | Scene3, options: Mapping[str, Any]) -> float:
    """The option, else :data:`PENETRATION_RATIO` in 2D and :data:`PENETRATION_RATIO_3D` in 3D."""
    if options["penetration_ratio"] is not None:
        return options["penetration_ratio"]
    return PENETRATION_RATIO_3D if scene.DOFS == 6 else PENETRATION_RATIO


def target_settlement(scene: Scene | Scene3, options: Mapping[str, Any]) -> float:
    """The settlement a run goes to [m]: the option, else the model's settlement_target, else a share of the
    masonry height."""
    if options["settlement"] is not None:
        return options["settlement"]
    if "settlement_target" in scene.model:
        return float(scene.model.settlement_target.values)
    return options["settlement_ratio"] * scene.masonry_height() * scene.scales.length


def plateau_tolerance(scene: Scene | Scene3, options: Mapping[str, Any]) -> float:
    """The option, else none when the run goes to the model's settlement_target (the damage there is the
    answer), else :data:`PLATEAU_TOLERANCE`."""
    if options["plateau_tolerance"] is not None:
        return options["plateau_tolerance"]
    return 0.0 if options["settlement"] is None and "settlement_target" in scene.model else PLATEAU_TOLERANCE


def make_controls(scene: Scene | Scene3, options: Mapping[str, Any]) -> Controls:
    length, force = scene.scales.length, scene.scales.force
    if options["contact_stiffness"] is not None:
        kn = options["contact_stiffness"] * length**2 / force
    else:
        kn = scene.base_pressure / (penetration_ratio(scene, options) * scene.unit_height)
    dt_critical = scene.critical_time_step(kn)
    dt = options["dt_safety"] * dt_critical
    height = scene.masonry_height()
    target = target_settlement(scene, options) / length
    rate = options["loading_rate"] * np.sqrt(height)
    target_time = target / rate if rate > 0 else 0.0
    record_steps = max(1, int(target_time / dt / options["records"])) if target > 0 else 2000
    return Controls(
        kn=kn,
        kt=options["shear_stiffness_ratio"] * kn,
        min_half=0.5 * options["min_contact_length"] * scene.unit_height,
        contact_damping=options["contact_damping"],
        dt=dt,
        dt_critical=dt_critical,
        damping=options["damping"],
        target=target,
        rate=rate,
        ramp_time=max(options["ramp_fraction"] * target_time, dt),
        load_ramp=options["load_ramp"] / scene.scales.time,
        gravity_time=(options["gravity_time"] or 0.0) / scene.scales.time,
        gravity_steps_expected=(GRAVITY_TIME_3D if scene.DOFS == 6 else GRAVITY_TIME) * float(np.sqrt(height)) / dt,
        rest_tolerance=options["rest_tolerance"],
        max_steps=options["max_steps"],
        record_steps=record_steps,
        call_steps=call_steps(step_seconds(scene.driven.size, scene.friction.size, polyhedra=scene.DOFS == 6)),
        threads=Threads.chosen(options["threads"], scene.driven.size, numba.config.NUMBA_NUM_THREADS),
        buffer=options["buffer_ratio"] * scene.unit_height,
        reclip=options["reclip_ratio"],
        max_penetration=0.25 * scene.unit_height,
        min_cos=float(np.cos(np.radians(options["max_contact_angle"]))),
        sleep_speed=options["sleep"] * rate,
        sleep_steps=options["sleep_steps"],
        wake_force=options["wake_force"],
        plateau_tolerance=plateau_tolerance(scene, options),
        plateau_window=options["plateau_window"],
        snapshots=tuple(v / length for v in options["snapshots"]) or series_snapshots(scene, target),
        search=searches(scene, options),
        search_first=options["search_first"],
        search_limit=options["search_limit"],
        search_tolerance=options["search_tolerance"],
        search_step_time=SEARCH_STEP_TIME,
        search_trial_time=SEARCH_TRIAL_TIME,
        collapse_motion=options["collapse_motion"] * scene.unit_height,
    )


#: A 3D run keeps this many snapshots evenly over its settlement when none are asked: its time series, which the
#: VTK export's ``.pvd`` collection plays in ParaView (a 1,126-block house: 54 kB each).
SERIES_SNAPSHOTS = 20


def series_snapshots(scene: Scene | Scene3, target: float) -> tuple[float, ...]:
    """The settlements (scaled) of a 3D run's default snapshots, :data:`SERIES_SNAPSHOTS` up to ``target``; none in
    2D or without a target."""
    if scene.DOFS != 6 or not target > 0:
        return ()
    return tuple(float(v) for v in np.linspace(target / SERIES_SNAPSHOTS, target, SERIES_SNAPSHOTS))


def searches(scene: Scene | Scene3, options: Mapping[str, Any]) -> bool:
    """The load-factor search runs when load_factor is auto, no support moves and the masonry has a live load."""
    return options["load_factor"] is None and not scene.moving.any() and bool(np.any(scene.live != 0))
