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
import masonryfw.plugin_api as mfp

from . import postprocess
from .compilation import Compilations
from .controls import make_controls
from .scene import Scene
from .scene3d import Scene3, scene_of
from .simulation import SETTLEMENT_PHASE, History, State, initial_state, run
from .simulation3d import initial_state3

LOG = logging.getLogger("masonryfw.fdem")
#: Load-factor search (scaled time, sqrt(length / g)): the ramp to a trial multiplier, the longest hold.
def solve(model: xr.Dataset, options: Mapping[str, Any], progress=mfp.no_progress) -> xr.Dataset:
    """Settlement response of ``model``: gravity to rest, then the support moves down slowly.

    Numba's compilation of the kernels on a first run is measured apart and reported as ``compile_time_s``
    (:mod:`.compilation`).
    """
    import numba
    from numba.core import event

    compilations = Compilations(options["mode"], progress)
    before = numba.get_num_threads()
    try:
        with event.install_listener("numba:compile", compilations):
            result = _solve(model, options, progress)
    finally:
        numba.set_num_threads(before)
    result.attrs["compile_time_s"] = compilations.seconds
    return result


def _solve(model: xr.Dataset, options: Mapping[str, Any], progress) -> xr.Dataset:
    scene = scene_of(model, options)  # the one the estimate made
    mfp.refuse_rigid_settlement(model, "fdem")
    controls = make_controls(scene, options)
    load = scene.dead + (options["load_factor"] or 0.0) * scene.live
    if isinstance(scene, Scene3):
        refuse_in_3d(options, controls)
        state = initial_state3(scene, controls)
    elif options["mode"] == "deformable":
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
    result = result_dataset3(scene, state, history) if isinstance(scene, Scene3) else \
        result_dataset(scene, state, history)
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
        fdem_threads=controls.threads.most_used(),
        fdem_thread_steps=", ".join(f"{count}: {steps}" for count, steps in sorted(controls.threads.steps_on.items())),
        fdem_face_pairs=int(state.pairs.faces.shape[0]),
        fdem_asleep_blocks=int((~scene.driven & (state.active == 0)).sum()),
        fdem_target_settlement=controls.target * scene.scales.length,
    )
    result.attrs.update(standing(scene, state))
    if not result.attrs["stood"]:
        LOG.warning("fdem: %s", mfp.standing_text(result))
    result.attrs.update(quasi_static_ratios(result))
    if result.attrs.get("unbalanced_ratio", 0.0) > mfp.QUASI_STATIC_RATIO:
        LOG.warning("fdem: the reaction history is dynamic, not quasi-static: the median unbalanced force ratio of "
                    "the settlement records is %.3g (over %g) and the kinetic energy %.3g of the stored; its minimum "
                    "depends on the loading; rerun with a smaller --option loading_rate (docs/fdem.md)",
                    result.attrs["unbalanced_ratio"], mfp.QUASI_STATIC_RATIO, result.attrs["kinetic_energy_ratio"])
    if state.trials:
        result.attrs["fdem_unstable_load_factor"] = state.collapse_bracket[1] if state.collapse_bracket[1] is not None \
            else np.nan
    if not state.interrupted:  # an interrupted run leaves the bar where it stopped
        progress(1.0, f"fdem: {state.stop_reason} after {state.steps} steps")
    return result


def refuse_in_3d(options: Mapping[str, Any], controls) -> None:
    """What fdem does not do in 3D yet, refused before the run: the CST mode and the load-factor search."""
    if options["mode"] == "deformable":
        raise mf.SolveError("fdem: mode = 'deformable' solves 2D models; a 3D model's blocks are rigid "
                            "(mode = 'rigid')")
    if controls.search:
        raise mf.SolveError("fdem: the load-factor search (no moving support, a live load) solves 2D models; give "
                            "a 3D model a moving support, or --option load_factor=<multiplier>")


def opening_meter(scene: Scene | Scene3):
    """The widest crack in the masonry and the widest base gap of a state's snapshot (``mf.widest_crack``,
    finite rotations)."""
    displacement = postprocess.block_displacement3 if isinstance(scene, Scene3) else postprocess.block_displacement

    def widest(snapshot: np.ndarray) -> mf.Cracks:
        return mf.widest_crack(scene.model, displacement(scene, snapshot), "finite")
    return widest


def standing(scene: Scene, state) -> dict:
    """Whether the masonry stood under its own weight (``stood``) and the gravity phase's largest block motion,
    the block and where it started (docs/format.md): a run whose masonry fell is no settlement's damage."""
    motion = getattr(state, "gravity_motion", None)
    if motion is None:  # interrupted before the first record of gravity
        return {"stood": 1}
    worst = int(np.argmax(motion))
    length = scene.scales.length
    return {"stood": int(not state.fell),
            "gravity_motion": float(motion[worst] * length), "gravity_motion_block": worst,
            "gravity_motion_x": float(scene.pos0[worst, 0] * length),
            "gravity_motion_y": float(scene.pos0[worst, 1] * length)}


def quasi_static_ratios(result: xr.Dataset) -> dict[str, float]:
    """How far the settlement records are from rest (docs/format.md): the medians of the unbalanced force ratio and
    of the kinetic over the stored elastic energy; none without settlement records."""
    settling = result.step_phase.values == SETTLEMENT_PHASE if "step_phase" in result else np.zeros(0, bool)
    if not settling.any():
        return {}
    stored = result.step_stored.values[settling]
    kinetic = result.step_kinetic_energy.values[settling] / np.where(stored > 0, stored, np.inf)
    return {"unbalanced_ratio": float(np.median(result.step_unbalanced_ratio.values[settling])),
            "kinetic_energy_ratio": float(np.median(kinetic))}


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
        "step_settlement": ("step", rows["settlement"] * length, mfp.variable_attrs("step_settlement")),
        "step_reaction": ("step", rows["reaction"] * f, mfp.variable_attrs("step_reaction")),
        "step_support_reaction": (("step", "block"),
                                  np.array([r.supports for r in history.records]).reshape(len(cracks), -1) * f,
                                  mfp.variable_attrs("step_support_reaction")),
        "step_crack_width_max": ("step", np.array([c.width for c in cracks]), mfp.variable_attrs("step_crack_width_max")),
        "step_crack_interface": ("step", np.array([c.interface for c in cracks], dtype=np.int32),
                                 mfp.variable_attrs("step_crack_interface")),
        "step_base_gap_max": ("step", np.array([c.base_gap for c in cracks]), mfp.variable_attrs("step_base_gap_max")),
        **wall_crack_variables(cracks),
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


def wall_crack_variables(cracks: list[mf.Cracks]) -> dict:
    """A building's history of each wall's widest crack and its joint (``mf.Cracks.wall_width``), else nothing."""
    if not cracks or not cracks[0].wall_width:
        return {}
    sw = ("step", "wall")
    return {"step_wall_crack_width_max": (sw, np.array([c.wall_width for c in cracks]),
                                          mfp.variable_attrs("step_wall_crack_width_max", "result3d")),
            "step_wall_crack_interface": (sw, np.array([c.wall_interface for c in cracks], dtype=np.int32),
                                          mfp.variable_attrs("step_wall_crack_interface", "result3d"))}


def result_dataset(scene: Scene, state: State, history: History) -> xr.Dataset:
    """The primary result variables: final displacements (finite rotations), contact forces, history."""
    normal, shear = postprocess.interface_forces(scene, state.pairs.faces, state.pairs.props, state.pairs.normal,
                                                 state.pairs.shear, state.pos)
    ie = ("interface", "end")
    data = {
        **mfp.motion_variables(postprocess.block_displacement(scene, state.pos)),
        "interface_normal_force": (ie, normal, mfp.variable_attrs("interface_normal_force")),
        "interface_shear_force": (ie, shear, mfp.variable_attrs("interface_shear_force")),
        **history_variables(scene, history),
    }
    if state.trials:
        factor, stable, motion = (np.array(column) for column in zip(*state.trials))
        data.update({
            "collapse_multiplier": ((), state.collapse_bracket[0], mfp.variable_attrs("collapse_multiplier")),
            "trial_load_factor": ("trial", factor, {"units": "1", "long_name": "multiplier of the live load tried"}),
            "trial_stable": ("trial", stable.astype(np.int8), {
                "units": "1", "long_name": "the wall came to rest under the trial multiplier",
                "flag_values": np.array([0, 1], np.int8), "flag_meanings": "unstable stable"}),
            "trial_largest_motion": ("trial", motion * scene.scales.length, {
                "units": "m", "long_name": "largest block motion from the last state at rest"}),
        })
    data.update(snapshot_variables(scene, history, postprocess.block_displacement))
    return xr.Dataset(data, attrs={"rotations": "finite", "flow_rule": "nonassociative"})


def snapshot_variables(scene, history: History, displacement) -> dict:
    """The snapshots' settlements and block motions, ``displacement(scene, snapshot)`` of each: ``(block, 3)``
    (x, y, rotation) in 2D, ``(block, 6)`` (displacement, rotation vector) in 3D."""
    if not history.snapshots:
        return {}
    motion = np.stack([displacement(scene, p) for _, p in history.snapshots])
    planar = motion.shape[-1] == 3
    return {
        "snapshot_settlement": ("snapshot", np.array([s for s, _ in history.snapshots]) * scene.scales.length,
                                {"units": "m", "long_name": "settlement at the snapshot (first record past the requested one)"}),
        "snapshot_block_displacement": (("snapshot", "block", "axis"), motion[..., :2] if planar else motion[..., :3],
                                        {"units": "m", "long_name": "block centroid displacement at the snapshot"}),
        "snapshot_block_rotation": ((("snapshot", "block"), motion[..., 2], {
            "units": "rad", "long_name": "block rotation at the snapshot"}) if planar else
            (("snapshot", "block", "axis"), motion[..., 3:], {
                "units": "rad", "long_name": "block rotation vector at the snapshot"})),
    }


def result_dataset3(scene: Scene3, state, history: History) -> xr.Dataset:
    """The primary result variables of a 3D run: final displacements (a rotation as its rotation vector), each
    interface's normal force at the end, the history."""
    motion = postprocess.block_displacement3(scene, state.snapshot())
    data = {
        "block_displacement": (("block", "axis"), motion[:, :3], mfp.variable_attrs("block_displacement", "result3d")),
        "block_rotation": (("block", "axis"), motion[:, 3:], mfp.variable_attrs("block_rotation", "result3d")),
        "interface_normal_force": ("interface", postprocess.interface_normal_forces3(scene, state.pairs.faces,
                                                                                    state.pairs.normal),
                                   mfp.variable_attrs("interface_normal_force", "result3d")),
        **history_variables(scene, history),
    }
    data.update(snapshot_variables(scene, history, postprocess.block_displacement3))
    return xr.Dataset(data, attrs={"rotations": "finite", "flow_rule": "nonassociative"})
