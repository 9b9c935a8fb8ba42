"""A model in words, as ``masonryfw info`` prints it: its counts, size, settlement profile, supports and loads."""
from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING

import numpy as np

from ..format.model3d import space
from ..format.roles import fixed_blocks, masonry_blocks, moving_blocks, support_blocks
from ..format.schema import flags
from ..geometry.polygons import block_bounds, node_block
from ..ground.profiles import Profile, model_profile

if TYPE_CHECKING:  # annotations only
    import xarray as xr


def describe_model(model: xr.Dataset) -> list[str]:
    """The lines that describe ``model`` (a checked model: its derived geometry is read)."""
    if space(model) == 3:
        return describe_model_3d(model)
    masonry = masonry_blocks(model.block_role.values)
    owner = node_block(model.block_node_count.values)
    x, y = model.node_x.values[masonry[owner]], model.node_y.values[masonry[owner]]
    lines = [f"title: {model.attrs.get('title', '')}",
             f"blocks: {model.sizes['block']} ({_counts(model.block_role.values, 'block_role')})",
             f"interfaces: {model.sizes.get('interface', 0)} ({_counts(model.interface_kind.values, 'interface_kind')})"]
    if x.size:
        lines += [f"wall: {np.ptp(x):.6g} m x {np.ptp(y):.6g} m (x {x.min():.6g}..{x.max():.6g}, "
                  f"y {y.min():.6g}..{y.max():.6g})",
                  f"thickness: {_span(model.block_thickness.values[masonry])}"]
    profile = model_profile(model)
    if profile is not None:
        lines.append(f"settlement profile: {profile_text(profile)}")
    notes = [f"  {note}" for note in str(model.attrs.get("laying_notes", "")).splitlines() if note]
    return lines + (["laid in its outline:", *notes] if notes else []) + ["supports:", *_support_lines(model), "loads:",
                                                                          *_load_lines(model)]


def describe_model_3d(model: xr.Dataset) -> list[str]:
    """A 3D model's lines: its counts, the extent of its masonry, its supports and the sums of its loads."""
    role = model.block_role.values
    masonry = masonry_blocks(role)
    owner = np.repeat(np.arange(role.size), model.block_node_count.values)
    points = np.c_[model.node_x.values, model.node_y.values, model.node_z.values][masonry[owner]]
    lines = [f"title: {model.attrs.get('title', '')}", "space: 3D",
             f"blocks: {model.sizes['block']} ({_counts(role, 'block_role')})",
             f"interfaces: {model.sizes.get('interface', 0)} ({_counts(model.interface_kind.values, 'interface_kind')})"]
    if points.size:
        low, high = points.min(axis=0), points.max(axis=0)
        lines.append("masonry: " + ", ".join(f"{c} {a:.6g}..{b:.6g} m" for c, a, b in zip("xyz", low, high))
                     + f"; volume {model.block_volume.values[masonry].sum():.6g} m3")
    profile = model_profile(model)
    if profile is not None and "settlement_axis" in model.attrs:
        axis = json.loads(model.attrs["settlement_axis"])
        degrees = math.degrees(math.atan2(-axis["direction"][0], axis["direction"][1])) % 180.0
        where = f"in plan at {degrees:.4g} degrees to x through ({axis['point'][0]:.6g}, {axis['point'][1]:.6g}) m"
        text = profile_text(profile, where) if profile.kind in ("tunnel", "gaussian") else \
            f"{profile_text(profile)}; its x measured across an axis {where}"
        if "face" in axis:
            driven = math.degrees(math.atan2(axis["direction"][0], -axis["direction"][1])) % 360.0
            text += (f"; the tunnel's face {axis['face']:.6g} m from that point along the axis, the tunnel driven "
                     f"towards {driven:.4g} degrees from x")
        lines.append(f"settlement profile: {text}")
    if "building_walls" in model.attrs:
        walls = json.loads(model.attrs["building_walls"])
        lines.append("walls: " + ", ".join(f"{w['name']} ({math.dist(w['start'], w['end']):.4g} m x "
                                           f"{w['height']:.4g} m, {w['thickness']:.4g} m thick)" for w in walls))
    supports = support_blocks(role)
    moving = moving_blocks(role)
    lines += ["supports:", f"  {int((supports & ~moving).sum())} fixed, {int(moving.sum())} moving (settlement "
                           "direction per unit t over ux uy uz rx ry rz)"]
    lines += [f"  block {b}: settlement direction ({', '.join(f'{d:.4g}' for d in model.settlement_direction.values[b])})"
              for b in np.flatnonzero(moving)[:10]]
    lines.append("loads:")
    for name in ("dead_load", "live_load"):
        for label, rows in (("masonry", ~supports), ("supports", supports)):
            total = model[name].values[rows].sum(axis=0)
            lines.append(f"  {name.replace('_', ' ')} on {label}: "
                         + ", ".join(f"F{c} = {v:.6g} N" for c, v in zip("xyz", total)))
    return lines


#: Flags a count names only where some block has them (few walls have arches).
SAID_WHEN_PRESENT = ("voussoir",)


def _counts(values: np.ndarray, flag_variable: str) -> str:
    meanings = flags(flag_variable)
    counts = np.bincount(np.asarray(values, dtype=np.int64), minlength=max(meanings.values()) + 1)
    return ", ".join(f"{meaning.replace('_', ' ')} {counts[value]}" for meaning, value in meanings.items()
                     if counts[value] or meaning not in SAID_WHEN_PRESENT)


def _span(values: np.ndarray) -> str:
    low, high = float(np.min(values)), float(np.max(values))
    return f"{low:.6g} m" if np.isclose(low, high) else f"{low:.6g}..{high:.6g} m"


def _support_lines(model: xr.Dataset) -> list[str]:
    """One line per support block: its x range and how it moves (supports are few)."""
    xmin, xmax, _, _ = block_bounds(model.node_x.values, model.node_y.values, model.block_node_count.values)
    lines = []
    for block in np.flatnonzero(support_blocks(model.block_role.values)):
        held = model.block_fixed.values[block]
        if fixed_blocks(model.block_role.values[block]):
            motion = f"fixed (held {' '.join(map(str, held))})"
        else:
            motion = "moving: " + _support_motion(model.settlement_direction.values[block], xmin[block], xmax[block],
                                                  float(model.block_centroid_x.values[block]))
        lines.append(f"  block {block}: x {xmin[block]:.6g}..{xmax[block]:.6g} m, {motion}")
    return lines


def profile_text(profile: Profile, axis: str | None = None) -> str:
    """A settlement profile in a line: its kind and parameters, a tunnel's trough and S_max. ``axis``: where its
    axis lies, said instead of its x (a building's, in plan)."""
    where = axis or f"at x {profile.center:g} m"
    if profile.kind == "tunnel":
        return (f"tunnel, V_L {profile.volume_loss:g} %, D {profile.diameter:g} m, axis {profile.depth:g} m deep "
                f"{where}, K {profile.trough_width_factor:g}: i {profile.width:.4g} m, S_max "
                f"{1e3 * profile.target:.4g} mm (settlement_target); segments {profile.segment:.4g} m")
    if profile.kind == "gaussian":
        sideways = f", ground moving towards the axis (z0 {profile.depth:g} m)" if profile.depth else ""
        return f"gaussian trough, axis {where}, i {profile.width:.4g} m{sideways}; segments {profile.segment:.4g} m"
    if profile.kind == "linear":
        return f"tilt from x {profile.start:g} m (rate 0) to x {profile.end:g} m (rate 1); segments {profile.segment:.4g} m"
    return f"table of {len(profile.points)} rates; segments {profile.segment:.4g} m"


def _support_motion(direction, x0: float, x1: float, centre_x: float) -> str:
    """What a moving support does per unit settlement parameter t, in words: its settlement (at its two ends
    when it turns), sideways motion and rotation, then the settlement direction itself."""
    ux, uy, rz = (float(d) for d in direction)
    raw = f"settlement direction ({', '.join(f'{d:.4g}' for d in direction)})"
    if rz == 0:
        sideways = f", sideways {ux:.4g}" if ux else ""
        return f"translates: settles {-uy:.4g}{sideways} per unit t; {raw}"
    left, right = -(uy + rz * (x0 - centre_x)) + 0.0, -(uy + rz * (x1 - centre_x)) + 0.0  # no "-0"
    return (f"translates and turns: settles {left:.4g} at its left end and {right:.4g} at its right, turns "
            f"{rz:.4g} rad per unit t; {raw}")


def _load_lines(model: xr.Dataset) -> list[str]:
    on_support = support_blocks(model.block_role.values)
    lines = []
    for name in ("dead_load", "live_load"):
        load = model[name].values
        for label, rows in (("masonry", ~on_support), ("supports", on_support)):
            fx, fy = load[rows, 0].sum(), load[rows, 1].sum()
            lines.append(f"  {name.replace('_', ' ')} on {label}: Fx = {fx:.6g} N, Fy = {fy:.6g} N")
    return lines
