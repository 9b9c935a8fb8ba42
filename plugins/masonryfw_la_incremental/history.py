"""From the configurations of a run to the result variables (the history schema fdem and jmm write).

One record per configuration that stands: the settlement parameter (or, under a live load, the largest
block translation and the multiplier), the settlement reaction of its limit state (la's
``(1 - alpha) R0`` of the moved configuration), every support's upward force, the widest crack and
base gap from the accumulated block motions with finite rotations (``mf.widest_crack``, the same
definition as fdem's), and every block's displacement and rotation.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

from .configuration import Reference
from .stepping import Configuration, Outcome


def support_reactions(ref: Reference, configuration: Configuration) -> np.ndarray:
    """``(block,)``: the upward force of every support on the wall [N] (0 for masonry blocks)."""
    wall, state = configuration.wall, configuration.state
    fy = state.normal * wall.normal[:, 1, None] + state.shear * wall.tangent[:, 1, None]  # on side 1, per end
    upward = np.zeros(ref.n_block)
    for side, sign in ((0, 1.0), (1, -1.0)):  # a support pushes the wall with the opposite of the wall on it
        np.add.at(upward, wall.sides[:, side], sign * fy.sum(axis=1))
    return np.where(ref.ground, upward, 0.0)


def resting_shares(model: xr.Dataset, ref: Reference) -> np.ndarray:
    """``(block,)``: the supports' upward forces at rest under the paper's convention (docs/format.md): each
    moving support its dead load's share, the fixed ones the rest of the weight by their length under the
    masonry."""
    ground = ref.ground
    sides = ref.wall.sides
    touching = ground[sides].any(axis=1) & ~ground[sides].all(axis=1)
    support = np.where(ground[sides[:, 0]], sides[:, 0], sides[:, 1])[touching]
    length = np.bincount(support, weights=ref.wall.length[touching], minlength=ref.n_block)
    shares = np.where(ref.wall.moving, ref.wall.dead[:, 1], 0.0)
    fixed = ground & ~ref.wall.moving
    weight = -float(ref.wall.dead[~ground, 1].sum())
    if length[fixed].sum() > 0:
        shares[fixed] = (weight - shares.sum()) * length[fixed] / length[fixed].sum()
    return shares


def largest_translation(pose: np.ndarray) -> float:
    return float(np.hypot(pose[:, 0], pose[:, 1]).max(initial=0.0))


@dataclass
class History:
    """The records of a run, appended as it goes (an interrupted run keeps what it has)."""

    model: xr.Dataset
    ref: Reference
    rows: list[dict] = field(default_factory=list)
    first_reaction: float = np.nan  # the limit state's at the first instant (la's collapse reaction)

    def __call__(self, configuration: Configuration) -> None:
        cracks = mf.widest_crack(self.model, configuration.pose, "finite")
        state = configuration.state
        at_rest = not self.rows and state.reaction is not None and mf.dead_reaction(self.model) > 0
        if not self.rows and state.reaction is not None:
            self.first_reaction = state.reaction
        self.rows.append({
            "t": configuration.t,
            # at rest: R0, the key numbers' dead reaction (none for a support moving sideways: R0 = 0 there)
            "reaction": mf.dead_reaction(self.model) if at_rest else np.nan if state.reaction is None
            else state.reaction,
            "alpha": state.alpha,
            "pose": configuration.pose.copy(),
            "supports": resting_shares(self.model, self.ref) if at_rest else support_reactions(self.ref, configuration),
            "crack": cracks.width,
            "crack_interface": cracks.interface,
            "base_gap": cracks.base_gap,
            "contacts": configuration.wall.n_interface,
        })

    def column(self, name: str) -> np.ndarray:
        return np.array([row[name] for row in self.rows])


def result_dataset(history: History, outcome: Outcome, driven: bool, flow_rule: str) -> xr.Dataset:
    """The primary result variables: the last configuration's block motions and the history."""
    pose = history.column("pose")
    data = {
        **mfp.motion_variables(pose[-1]),
        "step_block_displacement": (("step", "block", "axis"), pose[..., :2],
                                    mfp.variable_attrs("step_block_displacement")),
        "step_block_rotation": (("step", "block"), pose[..., 2], mfp.variable_attrs("step_block_rotation")),
        "step_crack_width_max": ("step", history.column("crack"), mfp.variable_attrs("step_crack_width_max")),
        "step_crack_interface": ("step", history.column("crack_interface").astype(np.int32),
                                 mfp.variable_attrs("step_crack_interface")),
        "step_base_gap_max": ("step", history.column("base_gap"), mfp.variable_attrs("step_base_gap_max")),
        "step_contacts": ("step", history.column("contacts").astype(np.int32),
                          {"units": "1", "long_name": "contacts of the moved configuration (interfaces found again)"}),
    }
    if driven:
        data.update({
            "step_settlement": ("step", history.column("t"), mfp.variable_attrs("step_settlement")),
            "step_reaction": ("step", history.column("reaction"), mfp.variable_attrs("step_reaction")),
            "step_support_reaction": (("step", "block"), history.column("supports"),
                                      mfp.variable_attrs("step_support_reaction")),
        })
    else:
        data.update({
            "step_load_factor": ("step", history.column("alpha"), mfp.variable_attrs("step_load_factor")),
            "step_displacement": ("step", np.array([largest_translation(p) for p in pose]),
                                  mfp.variable_attrs("step_displacement")),
        })
    if outcome.collapsed and outcome.capacity is not None:
        last = history.rows[-1]
        if driven:
            data["settlement_capacity"] = ((), outcome.capacity, mfp.variable_attrs("settlement_capacity"))
            data["capacity_reaction"] = ((), last["reaction"], mfp.variable_attrs("capacity_reaction"))
        else:
            data["displacement_capacity"] = ((), capacity_displacement(history),
                                             mfp.variable_attrs("displacement_capacity"))
    attrs = {"rotations": "finite", "flow_rule": flow_rule, "stop_reason": outcome.reason,
             "interrupted": int(outcome.interrupted)}
    if driven:
        attrs["la_incremental_first_reaction"] = history.first_reaction
    return xr.Dataset(data, attrs=attrs)


def capacity_displacement(history: History) -> float:
    """Where the multiplier falls to zero, between the last two records (linear in between)."""
    alpha = history.column("alpha")
    shift = np.array([largest_translation(row["pose"]) for row in history.rows])
    if alpha.size < 2 or alpha[-2] <= 0:
        return float(shift[-1])
    a, b = alpha[-2], alpha[-1]
    return float(shift[-2] + (shift[-1] - shift[-2]) * a / (a - b))
