"""What block results mean: one definition for every solver, the comparisons and the pictures.

A solver returns its primary fields (block displacements, contact forces,
histories); :func:`masonryfw.solve` derives the comparable fields below from
``block_displacement``, the same way whatever the solver:

- **relative motion** at an interface end: the motion of side 1 minus that of
  side 0 at the end point; ``opening = dv . n`` (>= 0 opens), ``slip = dv . t``.
  A mechanism (a velocity field, ``rotations = "small"``) moves points by the
  linearised rigid motion ``u_c + rz x (p - c)``; a displacement
  (``rotations = "finite"``) by ``u_c + (R(rz) - I)(p - c)``;
- **joint motion**: the largest ``|(max(opening, 0), slip)|`` of the joint's two
  ends (a closing end is compression, not a crack);
- **cracked** and **intact**: a joint is cracked where its motion is more than
  :data:`CRACK_THRESHOLD` (a tenth) of the largest masonry-joint motion, intact
  otherwise. One threshold for every solver, every plot, the comparisons, the
  report and the diagnosis; a user's ``threshold`` option re-derives the states,
  the indicator and the macro-blocks at another one (:func:`at_threshold`). A
  tenth keeps every joint one sees open in an amplified mechanism drawing and
  drops fdem's elastic contact motions (0.3-1 % of the largest on the ten bundled
  walls) and the round-off an interior-point solution leaves (1e-6 and below);
- **crack_indicator**: joint motion over the largest masonry-joint motion on
  cracked joints, 0 on intact joints and on joints between two supports (ground
  against ground). A continuum result (no block motion, plastic points
  ``qp_failure`` at ``qp_x``, ``qp_y``) gets the share of the points nearest to
  the joint that yield, 0 where that share is at most the threshold;
- **interface_state**: ``intact``; ``open`` when the slip stays within the
  threshold; ``slide`` when the slip exceeds it and the opening is no more than
  the flow rule's dilatancy of that slip (``tan(psi) |slip|``: ``mu |slip|`` for
  associative joints, 0 otherwise) plus the threshold; ``open_slide`` when the
  joint opens beyond that as well;
- **macro_block**: blocks connected through intact interfaces (supports
  included), labelled 0, 1, ... in order of their lowest block index.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..format.dofs import block_loads
from ..format.roles import masonry_blocks, masonry_joints, moving_blocks, support_blocks
from ..format.schema import flags, variable_attrs
from ..geometry.graph import connected_components
from ..geometry.polygons import block_offsets, model_scale, node_block
from ..runtime.errors import ModelError

if TYPE_CHECKING:  # annotations only
    import xarray as xr

#: A joint is cracked where it moves more than this share of the largest masonry-joint motion
#: (``crack_indicator > CRACK_THRESHOLD``), intact otherwise.
CRACK_THRESHOLD = 0.1
ROTATIONS = ("small", "finite")
FLOW_RULES = ("associative", "nonassociative")
DERIVED_RESULT_VARIABLES = ("interface_opening", "interface_slip", "interface_state", "crack_indicator",
                            "macro_block")

_STATE = flags("interface_state")


# ---------------------------------------------------------------- masks and scales

def polar_moment(node_x, node_y, block_node_count) -> np.ndarray:
    """Polar second moment of area of every polygon about its own centroid [m4].

    Shoelace sums in coordinates local to each block's first vertex (full
    precision far from the origin), moved to the centroid with the parallel-axis
    theorem. For a b x h rectangle: A (b^2 + h^2) / 12.
    """
    x = np.asarray(node_x, dtype=float)
    y = np.asarray(node_y, dtype=float)
    counts = np.asarray(block_node_count, dtype=np.int64)
    start = block_offsets(counts)[:-1]
    owner = node_block(counts)
    xs, ys = x - x[start][owner], y - y[start][owner]
    following = np.arange(x.size) + 1
    following[start + counts - 1] = start
    xn, yn = xs[following], ys[following]
    cross = xs * yn - xn * ys
    area = 0.5 * np.add.reduceat(cross, start)
    sx = np.add.reduceat((xs + xn) * cross, start) / 6.0  # first moments (area * centroid)
    sy = np.add.reduceat((ys + yn) * cross, start) / 6.0
    ixx = np.add.reduceat((ys * ys + ys * yn + yn * yn) * cross, start) / 12.0
    iyy = np.add.reduceat((xs * xs + xs * xn + xn * xn) * cross, start) / 12.0
    return ixx + iyy - (sx * sx + sy * sy) / area


@dataclass(frozen=True)
class ModelScales:
    """Reference sizes of a model, for solvers that work non-dimensionally.

    ``length``: bounding-box diagonal [m]; ``block``: square root of the median
    masonry block area [m]; ``weight``: weight of the units and lintels [N] (the
    total live load's magnitude for a weightless model, else 1).
    """

    length: float
    block: float
    weight: float


def model_scales(model: xr.Dataset) -> ModelScales:
    """The :class:`ModelScales` of a model with derived geometry."""
    length = model_scale(model.node_x.values, model.node_y.values)
    masonry = masonry_blocks(model.block_role.values)
    area = np.abs(model.block_area.values[masonry])
    block = float(np.sqrt(np.median(area))) if area.size and np.median(area) > 0 else length
    weight = float((model.block_unit_weight.values * np.abs(model.block_area.values)
                    * model.block_thickness.values)[masonry].sum())
    if not weight > 0:
        live = block_loads(model, "live")
        weight = float(np.hypot(live[:, 0], live[:, 1]).sum()) or 1.0
    return ModelScales(length, block, weight)


# ---------------------------------------------------------------- graphs

# ---------------------------------------------------------------- kinematics

def point_motion(u, centroid_x, centroid_y, px, py, owner, rotations: str = "small"):
    """Motion ``(ux, uy)`` of points ``p`` carried by blocks ``owner`` under block motions ``u`` (block, 3).

    ``rotations="small"``: the linearised rigid motion ``u_c + rz x (p - c)`` (a
    mechanism); ``"finite"``: ``u_c + (R(rz) - I)(p - c)`` (a displacement).
    """
    u = np.asarray(u, dtype=float)[owner]
    dx = np.asarray(px, dtype=float) - np.asarray(centroid_x)[owner]
    dy = np.asarray(py, dtype=float) - np.asarray(centroid_y)[owner]
    theta = u[..., 2]
    if rotations == "finite":
        c, s = np.cos(theta) - 1.0, np.sin(theta)
        return u[..., 0] + c * dx - s * dy, u[..., 1] + s * dx + c * dy
    return u[..., 0] - theta * dy, u[..., 1] + theta * dx


def rigid_fit(block, x, y, ux, uy, weight, centroid_x, centroid_y) -> np.ndarray:
    """The rigid motion ``(ux_c, uy_c, rz)`` (block, 3) closest to a field sampled at points.

    Point ``i`` at ``(x, y)`` lies in block ``block[i]`` and moves by ``(ux, uy)``;
    every block's motion minimises ``sum w |u - (u_c + rz x (p - c))|^2`` over its
    points, ``c`` its centroid. This is how a continuum result (a field over a mesh)
    gets block motions comparable with a discrete one's: with ``weight`` the
    quadrature weights, it is the L2 projection of the field onto rigid motions,
    and for a field that is rigid on a block it returns that motion exactly. A block
    with no point, or whose points cannot fix a rotation (all at one place), gets NaN.
    """
    n = len(centroid_x)
    block = np.asarray(block, dtype=np.int64)
    w = np.asarray(weight, dtype=float)
    rx = np.asarray(x, dtype=float) - np.asarray(centroid_x, dtype=float)[block]
    ry = np.asarray(y, dtype=float) - np.asarray(centroid_y, dtype=float)[block]

    def total(values):
        return np.bincount(block, weights=w * values, minlength=n)

    ones, sx, sy, srr = total(np.ones_like(rx)), total(rx), total(ry), total(rx * rx + ry * ry)
    normal = np.zeros((n, 3, 3))  # unknowns (u_cx, u_cy, rz); residuals ux - u_cx + rz ry, uy - u_cy - rz rx
    normal[:, 0, 0] = normal[:, 1, 1] = ones
    normal[:, 0, 2] = normal[:, 2, 0] = -sy
    normal[:, 1, 2] = normal[:, 2, 1] = sx
    normal[:, 2, 2] = srr
    ux, uy = np.asarray(ux, dtype=float), np.asarray(uy, dtype=float)
    rhs = np.stack([total(ux), total(uy), total(rx * uy - ry * ux)], axis=1)
    fitted = np.full((n, 3), np.nan)
    scale = np.maximum(srr, np.finfo(float).tiny)
    determined = (ones > 0) & (srr * ones - sx * sx - sy * sy > 1e-12 * scale * ones)
    fitted[determined] = np.linalg.solve(normal[determined], rhs[determined][..., None])[..., 0]
    return fitted


def relative_motion(model: xr.Dataset, u: np.ndarray, rotations: str) -> tuple[np.ndarray, np.ndarray]:
    """Opening and slip (interface, end) of block motions ``u`` (block, 3), side 1 minus side 0."""
    sides = model.interface_blocks.values.astype(np.int64)
    px, py = model.interface_x.values, model.interface_y.values
    cx, cy = model.block_centroid_x.values, model.block_centroid_y.values
    u0x, u0y = point_motion(u, cx, cy, px, py, sides[:, [0, 0]], rotations)
    u1x, u1y = point_motion(u, cx, cy, px, py, sides[:, [1, 1]], rotations)
    dx, dy = u1x - u0x, u1y - u0y
    nx, ny = model.interface_normal_x.values[:, None], model.interface_normal_y.values[:, None]
    tx, ty = model.interface_tangent_x.values[:, None], model.interface_tangent_y.values[:, None]
    return dx * nx + dy * ny, dx * tx + dy * ty


def joint_motion(opening: np.ndarray, slip: np.ndarray) -> np.ndarray:
    """Largest end motion ``|(max(opening, 0), slip)|`` of every interface."""
    return np.hypot(np.maximum(opening, 0.0), slip).max(axis=1)


def intact_threshold(motion: np.ndarray, masonry: np.ndarray, share: float = CRACK_THRESHOLD) -> float:
    """The joint motion at or below which a joint is intact: ``share`` of the largest masonry-joint motion."""
    return share * float(motion[masonry].max(initial=0.0))


def crack_indicator(motion: np.ndarray, masonry: np.ndarray, share: float = CRACK_THRESHOLD) -> np.ndarray:
    """Joint motion over the largest masonry-joint motion; 0 on intact and non-masonry joints."""
    largest = float(motion[masonry].max(initial=0.0))
    if largest <= 0:
        return np.zeros_like(motion, dtype=float)
    return np.where(masonry & (motion > share * largest), np.minimum(motion / largest, 1.0), 0.0)


def nearest_interface(model: xr.Dataset, x: np.ndarray, y: np.ndarray, spacing: float,
                      among: np.ndarray | None = None) -> np.ndarray:
    """Index of the interface nearest to each point ``(x, y)``, to within ``spacing / 2``; ``among`` (bool per
    interface) limits the search to those interfaces.

    A KD-tree of points sampled along every interface ``spacing`` apart, so no
    point-to-segment loop over all pairs.
    """
    from scipy.spatial import cKDTree  # here, not at the top: it adds 0.1 s to every CLI start

    index = np.arange(model.sizes["interface"]) if among is None else np.flatnonzero(among)
    ix, iy = model.interface_x.values[index], model.interface_y.values[index]
    length = np.hypot(ix[:, 1] - ix[:, 0], iy[:, 1] - iy[:, 0])
    samples = np.maximum(np.ceil(length / spacing).astype(int), 1) + 1
    owner = np.repeat(np.arange(length.size), samples)
    start = np.repeat(np.cumsum(samples) - samples, samples)
    fraction = (np.arange(samples.sum()) - start) / np.repeat(samples - 1, samples)
    sx = ix[owner, 0] + fraction * (ix[owner, 1] - ix[owner, 0])
    sy = iy[owner, 0] + fraction * (iy[owner, 1] - iy[owner, 0])
    _, nearest = cKDTree(np.c_[sx, sy]).query(np.c_[x, y])
    return index[owner[nearest]]


def plastic_crack_indicator(model: xr.Dataset, x: np.ndarray, y: np.ndarray, plastic: np.ndarray,
                            threshold: float = CRACK_THRESHOLD) -> np.ndarray:
    """Continuum ``crack_indicator``: the share of the points nearest to each joint that yield, where it is
    more than ``threshold``.

    Points go to their nearest interface to within a quarter of the points' median
    spacing (nearest-neighbour distance) or a sixteenth of the median joint length,
    whichever is smaller; a joint no point is nearest to, and a joint between two
    supports, gets 0.
    """
    from scipy.spatial import cKDTree

    points = np.c_[x, y]
    joint = float(np.median(model.interface_length.values))
    gap = float(np.median(cKDTree(points).query(points, k=2)[0][:, 1])) if len(points) > 1 else joint
    owner = nearest_interface(model, x, y, max(min(gap, joint / 8), 1e-6 * joint) / 2)
    n = model.sizes["interface"]
    total = np.bincount(owner, minlength=n)
    hits = np.bincount(owner, weights=np.asarray(plastic, dtype=float), minlength=n)
    share = np.divide(hits, total, out=np.zeros(n), where=total > 0)
    cracked = masonry_joints(model.block_role.values, model.interface_blocks.values) & (share > threshold)
    return np.where(cracked, share, 0.0)


def interface_states(opening: np.ndarray, slip: np.ndarray, dilatancy: np.ndarray | float,
                     threshold: float) -> np.ndarray:
    """int8 state of every interface (module docstring); ``threshold`` in the units of the motion."""
    moves = joint_motion(opening, slip) > threshold
    slips = np.abs(slip).max(axis=1) > threshold
    dilatant = np.asarray(dilatancy, dtype=float).reshape(-1, 1) * np.abs(slip)
    opens_beyond = (opening - dilatant).max(axis=1) > threshold
    state = np.full(opening.shape[0], _STATE["intact"], dtype=np.int8)
    state[moves & ~slips] = _STATE["open"]
    state[moves & slips & ~opens_beyond] = _STATE["slide"]
    state[moves & slips & opens_beyond] = _STATE["open_slide"]
    return state


def macro_blocks(n_block: int, interface_blocks: np.ndarray, state: np.ndarray) -> np.ndarray:
    """Label of the rigid macro-block of every block: connected through intact interfaces."""
    intact = np.asarray(interface_blocks)[np.asarray(state) == _STATE["intact"]]
    return connected_components(n_block, intact)


def dilatancy(model: xr.Dataset, flow_rule: str) -> np.ndarray:
    """Per interface, the opening per unit slip of a sliding joint: mu (associative) or 0."""
    if flow_rule == "associative":
        return model.interface_friction.values.astype(float)
    return np.zeros(model.sizes.get("interface", 0))


def derived_variables(model: xr.Dataset, u: np.ndarray, rotations: str, flow_rule: str,
                      share: float = CRACK_THRESHOLD) -> dict[str, tuple]:
    """The comparable result variables of block motions ``u`` (block, 3) on ``model`` (derived geometry)."""
    opening, slip = relative_motion(model, u, rotations)
    motion = joint_motion(opening, slip)
    masonry = masonry_joints(model.block_role.values, model.interface_blocks.values)
    state = interface_states(opening, slip, dilatancy(model, flow_rule), intact_threshold(motion, masonry, share))
    labels = macro_blocks(model.sizes["block"], model.interface_blocks.values, state)
    ie = ("interface", "end")
    return {
        "interface_opening": (ie, opening, variable_attrs("interface_opening")),
        "interface_slip": (ie, slip, variable_attrs("interface_slip")),
        "interface_state": (("interface",), state, variable_attrs("interface_state")),
        "crack_indicator": (("interface",), crack_indicator(motion, masonry, share), indicator_attrs(share)),
        "macro_block": (("block",), labels.astype(np.int32), variable_attrs("macro_block")),
    }


def indicator_attrs(threshold: float) -> dict:
    """``crack_indicator``'s attributes, with the threshold it was derived at (``crack_threshold``)."""
    return {**variable_attrs("crack_indicator"), "crack_threshold": float(threshold)}


def indicator_at(result: xr.Dataset, threshold: float = CRACK_THRESHOLD) -> np.ndarray:
    """``result``'s ``crack_indicator`` at a crack threshold: as stored when it was derived there (its
    attribute ``crack_threshold``), else from the relative motion at the joints of a block result, from the
    plastic points of a continuum one, or, for a result with only an indicator, the part of it above the
    threshold. The cheap part of :func:`at_threshold` (no states, no macro-blocks)."""
    indicator = np.asarray(result.crack_indicator.values, dtype=float)
    if result.crack_indicator.attrs.get("crack_threshold") == threshold:
        return indicator
    if "interface_opening" in result and "interface_slip" in result:
        motion = joint_motion(result.interface_opening.values, result.interface_slip.values)
        return crack_indicator(motion, masonry_joints(result.block_role.values, result.interface_blocks.values),
                               threshold)
    if "qp_failure" in result:
        return plastic_crack_indicator(result, result.qp_x.values, result.qp_y.values, result.qp_failure.values > 0,
                                       threshold)
    return np.where(indicator > threshold, indicator, 0.0)


def at_threshold(result: xr.Dataset, threshold: float = CRACK_THRESHOLD) -> xr.Dataset:
    """``result`` with ``crack_indicator`` (:func:`indicator_at`), ``interface_state`` and ``macro_block``
    (from the relative motion at the joints, when the result has it) derived at another crack threshold (a
    user's ``threshold`` option). A result derived at ``threshold`` already is returned as it is."""
    if "crack_indicator" not in result:
        return result
    derived = result.crack_indicator.attrs.get("crack_threshold") == threshold
    if derived and ("interface_state" in result or "interface_opening" not in result):
        return result
    fields = {"crack_indicator": ("interface", indicator_at(result, threshold), indicator_attrs(threshold))}
    if "interface_opening" in result and "interface_slip" in result:
        opening, slip = result.interface_opening.values, result.interface_slip.values
        masonry = masonry_joints(result.block_role.values, result.interface_blocks.values)
        rule = str(result.attrs.get("flow_rule", "nonassociative"))
        limit = intact_threshold(joint_motion(opening, slip), masonry, threshold)
        state = interface_states(opening, slip, dilatancy(result, rule), limit)
        labels = macro_blocks(result.sizes["block"], result.interface_blocks.values, state)
        fields.update(interface_state=("interface", state, variable_attrs("interface_state")),
                      macro_block=("block", labels.astype(np.int32), variable_attrs("macro_block")))
    return result.assign(fields)


def cracked_joints(result: xr.Dataset, threshold: float = CRACK_THRESHOLD) -> np.ndarray:
    """bool per interface: the joints ``result`` has cracked at ``threshold`` (:func:`indicator_at` > 0); every
    plot, comparison, report and diagnosis counts cracks through this."""
    if "crack_indicator" not in result:
        return np.zeros(result.sizes.get("interface", 0), dtype=bool)
    return indicator_at(result, threshold) > 0


# ---------------------------------------------------------------- the reaction of a settlement

def settlement_weights(model: xr.Dataset) -> np.ndarray:
    """``(block, 3)``: every moving support's ``settlement_direction``, 0 for other blocks: the weights of
    :func:`settlement_reaction`."""
    moving = moving_blocks(model.block_role.values)
    return np.where(moving[:, None], np.asarray(model.settlement_direction.values, dtype=float), 0.0)


def settlement_reaction(model: xr.Dataset, wrench: np.ndarray) -> np.ndarray:
    """The **settlement reaction** [N] of support wrenches ``wrench`` ``(..., block, 3)``: the force (x, y)
    and moment (about each block's centroid) the *wall exerts on* each support.

    The force conjugate to the settlement parameter t: the work the supports' reactions do on the wall
    per unit of t, with the sign flipped, ``sum_s F_s . d_s``. With one support translating down at rate 1
    it is that support's upward vertical reaction; over a settlement profile (t = S_max) every part of
    the settling ground counts by its settlement over S_max, its rotation and sideways motion included.
    It is the one reaction equilibrium fixes with one settlement parameter (la's alpha is a share of it:
    ``(1 - alpha) R0`` at collapse), it converges as the ground is cut into finer segments, and it stays
    defined when the whole base settles (a rigid translation leaves it at R0; a trough makes it drop).
    """
    return np.einsum("...bd,bd->...", np.asarray(wrench, dtype=float), settlement_weights(model))


def refuse_rigid_settlement(model: xr.Dataset, solver: str) -> None:
    """A :class:`ModelError` when every support moves and all by the same translation: the whole wall
    then follows the ground as one rigid body, nothing in it deforms and the settlement reaction stays R0."""
    role = np.asarray(model.block_role.values)
    ground = support_blocks(role)
    moving = moving_blocks(role)
    direction = np.asarray(model.settlement_direction.values, dtype=float)[ground]
    if moving.any() and moving.sum() == ground.sum() and np.all(direction[:, 2] == 0) \
            and np.allclose(direction, direction[0], rtol=0.0, atol=1e-12 * np.abs(direction).max()):
        raise ModelError(f"{solver}: every support moves by the same translation "
                         f"{' '.join(f'{d:.6g}' for d in direction[0])} per unit settlement: the wall follows the "
                         "ground as one rigid body and nothing in it deforms; keep part of the base fixed or let "
                         "the supports settle at different rates (a [settlement] profile)")


def dead_reaction(model: xr.Dataset) -> float:
    """The settlement reaction of the model's dead loads on the moving supports [N] (R0, the paper's
    convention: each moving support carries ``W L_s / L_total`` up): :func:`settlement_reaction` of the
    force the wall would exert on them (their dead load, down), a sum weighted by the supports' rates."""
    return float(settlement_reaction(model, -block_loads(model, "dead")))
