"""The ``fdem`` solve function: options -> scene -> time loop -> result variables."""
from __future__ import annotations

import logging
import time
from typing import Any, Mapping

import numpy as np
import xarray as xr

import masonryfw as mf

from . import postprocess
from .options import OPTIONS
from .scene import Scene, build_scene
from .simulation import Controls, History, State, run

LOG = logging.getLogger("masonryfw.fdem")

def parse_snapshots(text: str) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in text.split(",") if v.strip())
    except ValueError:
        raise mf.PluginError(f"option 'snapshots': {text!r} is not a comma-separated list of numbers") from None
    return values


def check_options(options: Mapping[str, Any]) -> None:
    positive = ("min_contact_length", "loading_rate", "dt_safety", "penetration_ratio", "shear_stiffness_ratio",
                "records", "sleep_steps", "buffer_ratio", "max_contact_angle", "max_steps", "rest_tolerance")
    for name in positive:
        if not options[name] > 0:
            raise mf.PluginError(f"option {name!r}: must be positive, got {options[name]!r}")
    non_negative = ("settlement", "settlement_ratio", "damping", "contact_damping", "contact_stiffness", "gravity_time", "load_ramp",
                    "plateau_tolerance", "plateau_window", "ramp_fraction", "crack_threshold", "sleep")
    for name in non_negative:
        if not options[name] >= 0:
            raise mf.PluginError(f"option {name!r}: must be >= 0, got {options[name]!r}")
    if options["damping"] >= 1:
        raise mf.PluginError(f"option 'damping': must be below 1, got {options['damping']!r}")
    if not 0 < options["max_contact_angle"] < 90:
        raise mf.PluginError(f"option 'max_contact_angle': must be in (0, 90) degrees, got {options['max_contact_angle']!r}")


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


def make_controls(scene: Scene, options: Mapping[str, Any]) -> Controls:
    length, force = scene.scales.length, scene.scales.force
    if options["contact_stiffness"] > 0:
        kn = options["contact_stiffness"] * length**2 / force
    else:
        base_pressure = 1.0 / scene.support_length
        kn = base_pressure / (options["penetration_ratio"] * scene.unit_height)
    dt_critical = critical_time_step(scene, kn)
    dt = options["dt_safety"] * dt_critical
    height = masonry_height(scene)
    target = options["settlement"] / length if options["settlement"] > 0 else options["settlement_ratio"] * height
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
        gravity_time=options["gravity_time"] / scene.scales.time,
        rest_tolerance=options["rest_tolerance"],
        max_steps=options["max_steps"],
        record_steps=record_steps,
        buffer=options["buffer_ratio"] * scene.unit_height,
        max_penetration=0.25 * scene.unit_height,
        min_cos=float(np.cos(np.radians(options["max_contact_angle"]))),
        sleep_speed=options["sleep"] * rate,
        sleep_steps=options["sleep_steps"],
        plateau_tolerance=options["plateau_tolerance"],
        plateau_window=options["plateau_window"],
        snapshots=tuple(v / length for v in parse_snapshots(options["snapshots"])),
    )


def solve(model: xr.Dataset, options: Mapping[str, Any], progress=mf.no_progress) -> xr.Dataset:
    """Settlement response of ``model``: gravity to rest, then the support moves down slowly."""
    options = {o.name: o.default for o in OPTIONS} | dict(options)
    check_options(options)
    clock = time.perf_counter()
    scene = build_scene(model)
    controls = make_controls(scene, options)
    load = scene.dead + options["load_factor"] * scene.live
    deformable_mode = options["mode"] == "deformable"
    if deformable_mode:
        from . import deformable, deformable_simulation

        deformable.check_supported(scene)
        mesh = deformable.build_mesh(model, scene)
        controls = deformable_simulation.deformable_controls(mesh, scene, controls, options["dt_safety"])
    LOG.info("fdem: dt = %.4g s (dt_crit = %.4g s, safety %.2g), kn = %.4g N/m2",
             controls.dt * scene.scales.time, controls.dt_critical * scene.scales.time,
             options["dt_safety"], controls.kn * scene.scales.force / scene.scales.length**2)
    progress(0.0, f"fdem: dt = {controls.dt * scene.scales.time:.3g} s "
                  f"(dt_crit = {controls.dt_critical * scene.scales.time:.3g} s)")
    if deformable_mode:
        state, history = deformable_simulation.run(scene, controls, mesh, load, progress)
    else:
        state, history = run(scene, controls, load, progress)
    result = result_dataset(model, scene, controls, state, history, options)
    result.attrs.update(
        fdem_mode=options["mode"],
        fdem_dt_s=controls.dt * scene.scales.time,
        fdem_dt_critical_s=controls.dt_critical * scene.scales.time,
        fdem_contact_stiffness=controls.kn * scene.scales.force / scene.scales.length**2,
        fdem_steps=int(state.steps),
        fdem_gravity_steps=int(state.gravity_steps),
        fdem_rebuilds=int(state.rebuilds),
        fdem_face_pairs=int(state.faces.shape[0]),
        fdem_asleep_blocks=int((~scene.driven & (state.active == 0)).sum()),
        fdem_stop_reason=state.stop_reason,
        fdem_interrupted=int(state.interrupted),
        fdem_target_settlement=controls.target * scene.scales.length,
        fdem_wall_time_s=time.perf_counter() - clock,
    )
    progress(1.0, f"fdem: {state.stop_reason} after {state.steps} steps")
    return result


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

    return {
        "step_settlement": ("step", rows["settlement"] * length, mf.variable_attrs("step_settlement")),
        "step_reaction": ("step", rows["reaction"] * f, mf.variable_attrs("step_reaction")),
        "step_phase": ("step", rows["phase"].astype(np.int8),
                       {"units": "1", "long_name": "analysis phase", "flag_values": np.array([0, 1], np.int8),
                        "flag_meanings": "gravity settlement"}),
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


def result_dataset(model: xr.Dataset, scene: Scene, controls: Controls, state: State, history: History,
                   options: Mapping[str, Any]) -> xr.Dataset:
    u = postprocess.block_displacement(scene, state.pos)
    opening, slip = postprocess.relative_motion(model, u)
    motion = np.hypot(opening, slip).max(axis=1)
    masonry = postprocess.masonry_joints(model)
    threshold = options["crack_threshold"] * motion[masonry].max(initial=0.0)
    state_flags = postprocess.interface_states(opening, slip, threshold)
    crack = postprocess.crack_indicator(motion, masonry, threshold)
    macro = postprocess.macro_blocks(model.sizes["block"], model.interface_blocks.values, state_flags)
    normal, shear = postprocess.interface_forces(model, scene, state.faces, state.props, state.normal,
                                                 state.shear, state.pos)
    ie = ("interface", "end")
    data = {
        "block_displacement": (("block", "dof"), u, mf.variable_attrs("block_displacement")),
        "interface_opening": (ie, opening, mf.variable_attrs("interface_opening")),
        "interface_slip": (ie, slip, mf.variable_attrs("interface_slip")),
        "interface_normal_force": (ie, normal, mf.variable_attrs("interface_normal_force")),
        "interface_shear_force": (ie, shear, mf.variable_attrs("interface_shear_force")),
        "interface_state": ("interface", state_flags, mf.variable_attrs("interface_state")),
        "crack_indicator": ("interface", crack, mf.variable_attrs("crack_indicator")),
        "macro_block": ("block", macro.astype(np.int32), mf.variable_attrs("macro_block")),
        **history_variables(scene, history),
    }
    if history.snapshots:
        data["snapshot_settlement"] = ("snapshot", np.array([s for s, _ in history.snapshots]) * scene.scales.length,
                                       {"units": "m", "long_name": "settlement at the snapshot (first record past the requested one)"})
        data["snapshot_block_displacement"] = (
            ("snapshot", "block", "dof"),
            np.stack([postprocess.block_displacement(scene, p) for _, p in history.snapshots]),
            {"units": "m m rad", "long_name": "block displacement at the snapshot settlement"},
        )
    masonry_blocks = ~scene.driven
    result = xr.Dataset(data)
    result.attrs.update(
        fdem_crack_threshold_m=float(threshold),
        fdem_macro_blocks=int(macro.max(initial=-1) + 1),
        fdem_masonry_macro_blocks=int(np.unique(macro[masonry_blocks]).size),
    )
    return result
