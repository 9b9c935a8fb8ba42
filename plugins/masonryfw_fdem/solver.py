"""The ``fdem`` solve function: options -> scene -> time loop -> primary result variables.

The core derives the comparable fields from the final block positions:
``rotations = "finite"`` (a displacement) and ``flow_rule = "nonassociative"``
(the Coulomb contacts slide without dilatancy).
"""
from __future__ import annotations

import logging
from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr

import masonryfw as mf

from . import estimate, postprocess
from .scene import Scene, build_scene
from .simulation import Controls, History, State, initial_state, run

LOG = logging.getLogger("masonryfw.fdem")
#: Load-factor search (scaled time, sqrt(length / g)): the ramp to a trial multiplier, the longest hold.
SEARCH_STEP_TIME = 1.0
SEARCH_TRIAL_TIME = 20.0


def critical_time_step(scene: Scene, kn: float) -> float:
    """2 / omega_max, omega^2 bounded per free block by the stiffness of springs all round
    its perimeter: kn P / m in translation, kn P R^2 / I in rotation."""
    free = ~scene.driven
    translation = kn * scene.perimeter[free] / scene.mass[free, 0]
    rotation = kn * scene.perimeter[free] * scene.radius[free] ** 2 / scene.mass[free, 2]
    omega = np.sqrt(max(translation.max(initial=0.0), rotation.max(initial=0.0)))
    return 2.0 / omega if omega > 0 else np.inf


def masonry_height(scene: Scene) -> float:
    """Height of the masonry (non-dimensional): top of the highest minus bottom of the lowest free block."""
    y = scene.pos0[:, 1][np.repeat(np.arange(scene.driven.size), np.diff(scene.offs))] + scene.ly
    free_nodes = ~np.repeat(scene.driven, np.diff(scene.offs))
    return float(np.ptp(y[free_nodes]))


#: The reaction plateau that stops a run when the target is not the model's own (share of the dead reaction).
PLATEAU_TOLERANCE = 0.005


def target_settlement(scene: Scene, options: Mapping[str, Any]) -> float:
    """The settlement a run goes to [m]: the option, else the model's settlement_target, else a share of the
    masonry height."""
    if options["settlement"] is not None:
        return options["settlement"]
    if "settlement_target" in scene.model:
        return float(scene.model.settlement_target.values)
    return options["settlement_ratio"] * masonry_height(scene) * scene.scales.length


def plateau_tolerance(scene: Scene, options: Mapping[str, Any]) -> float:
    """The option, else none when the run goes to the model's settlement_target (the damage there is the
    answer), else :data:`PLATEAU_TOLERANCE`."""
    if options["plateau_tolerance"] is not None:
        return options["plateau_tolerance"]
    return 0.0 if options["settlement"] is None and "settlement_target" in scene.model else PLATEAU_TOLERANCE


def make_controls(scene: Scene, options: Mapping[str, Any]) -> Controls:
    length, force = scene.scales.length, scene.scales.force
    if options["contact_stiffness"] is not None:
        kn = options["contact_stiffness"] * length**2 / force
    else:
        base_pressure = 1.0 / scene.support_length
        kn = base_pressure / (options["penetration_ratio"] * scene.unit_height)
    dt_critical = critical_time_step(scene, kn)
    dt = options["dt_safety"] * dt_critical
    height = masonry_height(scene)
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
        rest_tolerance=options["rest_tolerance"],
        max_steps=options["max_steps"],
        record_steps=record_steps,
        buffer=options["buffer_ratio"] * scene.unit_height,
        max_penetration=0.25 * scene.unit_height,
        min_cos=float(np.cos(np.radians(options["max_contact_angle"]))),
        sleep_speed=options["sleep"] * rate,
        sleep_steps=options["sleep_steps"],
        wake_force=options["wake_force"],
        plateau_tolerance=plateau_tolerance(scene, options),
        plateau_window=options["plateau_window"],
        snapshots=tuple(v / length for v in options["snapshots"]),
        search=searches(scene, options),
        search_first=options["search_first"],
        search_limit=options["search_limit"],
        search_tolerance=options["search_tolerance"],
        search_step_time=SEARCH_STEP_TIME,
        search_trial_time=SEARCH_TRIAL_TIME,
        collapse_motion=options["collapse_motion"] * scene.unit_height,
    )


def searches(scene: Scene, options: Mapping[str, Any]) -> bool:
    """The load-factor search runs when load_factor is auto, no support moves and the masonry has a live load."""
    return options["load_factor"] is None and not scene.moving.any() and bool(np.any(scene.live != 0))


def solve(model: xr.Dataset, options: Mapping[str, Any], progress=mf.no_progress) -> xr.Dataset:
    """Settlement response of ``model``: gravity to rest, then the support moves down slowly.

    Numba's compilation (or cache loading) of the kernels on a first run is
    measured apart and reported as ``compile_time_s``.
    """
    import numba
    from numba.core import event

    compiling = event.TimingListener()
    threads = estimate.threads(options, model.sizes["block"])
    before = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        with event.install_listener("numba:compile", compiling):
            result = _solve(model, options, progress)
    finally:
        numba.set_num_threads(before)
    result.attrs["compile_time_s"] = float(compiling.duration) if compiling.done else 0.0
    result.attrs["fdem_threads"] = threads
    return result


def _solve(model: xr.Dataset, options: Mapping[str, Any], progress) -> xr.Dataset:
    scene = build_scene(model)
    mf.refuse_rigid_settlement(model, "fdem")
    controls = make_controls(scene, options)
    load = scene.dead + (options["load_factor"] or 0.0) * scene.live
    if options["mode"] == "deformable":
        from . import deformable, deformable_simulation

        deformable.check_supported(scene)
        mesh = deformable.build_mesh(model, scene)
        controls = deformable_simulation.deformable_controls(mesh, scene, controls, options["dt_safety"])
        state = deformable_simulation.initial_state(scene, controls, mesh, load)
    else:
        state = initial_state(scene, controls)
    LOG.info("fdem: dt = %.4g s (dt_crit = %.4g s, safety %.2g), kn = %.4g N/m2",
             controls.dt * scene.scales.time, controls.dt_critical * scene.scales.time,
             options["dt_safety"], controls.kn * scene.scales.force / scene.scales.length**2)
    progress(0.0, f"fdem: dt = {controls.dt * scene.scales.time:.3g} s "
                  f"(dt_crit = {controls.dt_critical * scene.scales.time:.3g} s)")
    history = run(scene, controls, state, load, progress, opening_meter(scene))
    result = result_dataset(scene, state, history)
    result.attrs.update(
        stop_reason=state.stop_reason,
        interrupted=int(state.interrupted),
        fdem_mode=options["mode"],
        fdem_dt_s=controls.dt * scene.scales.time,
        fdem_dt_critical_s=controls.dt_critical * scene.scales.time,
        fdem_contact_stiffness=controls.kn * scene.scales.force / scene.scales.length**2,
        fdem_steps=int(state.steps),
        fdem_gravity_steps=int(state.gravity_steps),
        fdem_rebuilds=int(state.rebuilds),
        fdem_face_pairs=int(state.faces.shape[0]),
        fdem_asleep_blocks=int((~scene.driven & (state.active == 0)).sum()),
        fdem_target_settlement=controls.target * scene.scales.length,
    )
    if state.trials:
        result.attrs["fdem_unstable_load_factor"] = state.collapse_bracket[1] if state.collapse_bracket[1] is not None \
            else np.nan
    if not state.interrupted:  # an interrupted run leaves the bar where it stopped
        progress(1.0, f"fdem: {state.stop_reason} after {state.steps} steps")
    return result


def opening_meter(scene: Scene):
    """The widest crack in the masonry and the widest base gap of block positions (``mf.widest_crack``,
    finite rotations)."""
    def widest(pos: np.ndarray) -> mf.Cracks:
        return mf.widest_crack(scene.model, postprocess.block_displacement(scene, pos), "finite")
    return widest


def history_variables(scene: Scene, history: History) -> dict:
    rows = history.table()
    f, length = scene.scales.force, scene.scales.length
    energy = f * length
    work_gravity = rows["work_gravity"] * energy
    work_support = rows["work_support"] * energy
    dissipated = (rows["dissipated_damping"] + rows["dissipated_friction"] + rows["released"]) * energy
    kinetic = rows["kinetic"] * energy
    stored = rows["stored"] * energy
    scale = np.maximum.accumulate(np.maximum(np.abs(work_gravity), np.abs(work_support)))
    error = (work_gravity + work_support - kinetic - dissipated - stored) / np.where(scale > 0, scale, 1.0)

    def var(values, units, long_name):
        return ("step", values, {"units": units, "long_name": long_name})

    cracks = [r.cracks for r in history.records]
    settling = {
        "step_settlement": ("step", rows["settlement"] * length, mf.variable_attrs("step_settlement")),
        "step_reaction": ("step", rows["reaction"] * f, mf.variable_attrs("step_reaction")),
        "step_support_reaction": (("step", "block"),
                                  np.array([r.supports for r in history.records]).reshape(len(cracks), -1) * f,
                                  mf.variable_attrs("step_support_reaction")),
        "step_crack_width_max": ("step", np.array([c.width for c in cracks]), mf.variable_attrs("step_crack_width_max")),
        "step_crack_interface": ("step", np.array([c.interface for c in cracks], dtype=np.int32),
                                 mf.variable_attrs("step_crack_interface")),
        "step_base_gap_max": ("step", np.array([c.base_gap for c in cracks]), mf.variable_attrs("step_base_gap_max")),
    } if scene.moving.any() else {
        "step_load_factor": var(rows["load_factor"], "1", "multiplier of the live load (tried) at the record"),
    }
    return {
        **settling,
        "step_phase": ("step", rows["phase"].astype(np.int8),
                       {"units": "1", "long_name": "analysis phase", "flag_values": np.array([0, 1, 2], np.int8),
                        "flag_meanings": "gravity settlement load_factor_search"}),
        "step_time": var(rows["time"] * scene.scales.time, "s", "simulated time"),
        "step_kinetic_energy": var(kinetic, "J", "kinetic energy of the blocks"),
        "step_work_gravity": var(work_gravity, "J", "work of the applied (dead + factored live) loads"),
        "step_work_support": var(work_support, "J", "work of the moving supports on the wall"),
        "step_dissipated": var(dissipated, "J",
                               "energy dissipated by damping and friction, and released by lost contacts"),
        "step_dissipated_damping": var(rows["dissipated_damping"] * energy, "J", "energy dissipated by the local damping"),
        "step_dissipated_friction": var(rows["dissipated_friction"] * energy, "J",
                                        "energy dissipated by friction and broken bonds"),
        "step_released": var(rows["released"] * energy, "J",
                             "spring energy lost when two faces slid apart while in contact (numerical)"),
        "step_stored": var(stored, "J", "elastic energy stored in the contact springs (and the blocks' strain in mode=deformable)"),
        "step_energy_error": var(error, "1", "(work in - kinetic - dissipated - stored) / largest work so far"),
        "step_unbalanced_ratio": var(rows["unbalanced"], "1", "unbalanced force / applied load"),
    }


def result_dataset(scene: Scene, state: State, history: History) -> xr.Dataset:
    """The primary result variables: final displacements (finite rotations), contact forces, history."""
    normal, shear = postprocess.interface_forces(scene, state.faces, state.props, state.normal, state.shear, state.pos)
    ie = ("interface", "end")
    data = {
        **mf.motion_variables(postprocess.block_displacement(scene, state.pos)),
        "interface_normal_force": (ie, normal, mf.variable_attrs("interface_normal_force")),
        "interface_shear_force": (ie, shear, mf.variable_attrs("interface_shear_force")),
        **history_variables(scene, history),
    }
    if state.trials:
        factor, stable, motion = (np.array(column) for column in zip(*state.trials))
        data.update({
            "collapse_multiplier": ((), state.collapse_bracket[0], mf.variable_attrs("collapse_multiplier")),
            "trial_load_factor": ("trial", factor, {"units": "1", "long_name": "multiplier of the live load tried"}),
            "trial_stable": ("trial", stable.astype(np.int8), {
                "units": "1", "long_name": "the wall came to rest under the trial multiplier",
                "flag_values": np.array([0, 1], np.int8), "flag_meanings": "unstable stable"}),
            "trial_largest_motion": ("trial", motion * scene.scales.length, {
                "units": "m", "long_name": "largest block motion from the last state at rest"}),
        })
    if history.snapshots:
        motion = np.stack([postprocess.block_displacement(scene, p) for _, p in history.snapshots])
        data["snapshot_settlement"] = ("snapshot", np.array([s for s, _ in history.snapshots]) * scene.scales.length,
                                       {"units": "m", "long_name": "settlement at the snapshot (first record past the requested one)"})
        data["snapshot_block_displacement"] = (("snapshot", "block", "axis"), motion[..., :2],
                                               {"units": "m", "long_name": "block centroid displacement at the snapshot"})
        data["snapshot_block_rotation"] = (("snapshot", "block"), motion[..., 2],
                                           {"units": "rad", "long_name": "block rotation at the snapshot"})
    return xr.Dataset(data, attrs={"rotations": "finite", "flow_rule": "nonassociative"})
