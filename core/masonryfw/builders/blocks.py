"""From blocks (polygons with roles), a material, supports and a loading to a model dataset.

The one place where a model's interfaces, interface kinds, support kinematics
and loads are made; the parametric builder, the import of drawings and
:mod:`masonryfw.testing` all assemble their models here. Conventions
(docs/format.md):

- interfaces: the common segments of the blocks' collinear opposite edges
  (:func:`masonryfw.detect_interfaces`), but none between two supports (ground
  against ground carries nothing the analysis needs);
- kinds: ``support`` when a side is a support, else ``bed`` (horizontal),
  ``head`` (vertical) or ``other`` (inclined);
- loads: every unit and lintel carries its weight as dead load. Settlement
  loading: the masonry weight W is spread uniformly over the wall-on-support
  contact length L_total, so a moving support of contact length L_m carries the
  upward dead load ``W L_m / L_total`` and the same live load downward. Tilt
  loading: the weight acts horizontally as live load on every unit and lintel,
  and every support is held;
- a moving support translates (vertically by default: ``block_fixed`` 1 0 1, direction
  0 -1 0; along any ``direction``, its live load along it too: a springing moving out), rotates about a pivot (free, the small rotation that moves its
  centroid down by 1), either scaled by its ``rate``, or
  is a segment of a continuous ground (free: its top edge follows the ground's
  motion given at the edge's two ends, :func:`ground_direction`): all moving
  supports move as ``u_s = t * settlement_direction_s`` with one settlement
  parameter ``t``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from ..format.dofs import block_loads, load_variables
from ..format.roles import ROLE, support_blocks
from ..format.schema import flags, format_header, variable_attrs
from ..geometry.interfaces import detect_interfaces
from ..geometry.polygons import polygon_area_centroid
from ..readers.material import Material
from ..runtime.errors import SpecError

DOF_NAMES = ("ux", "uy", "rz")
#: Position tolerance of the interface kinds, relative to the interface length.
KIND_TOLERANCE = 1.0e-9
#: Memory a built 2D block takes (measured: 1.3 kB at 23,090 units, the build's peak less the start-up's; 1.1 kB a
#: block between the gable house's outline laid in 4,364 and in 17,793 blocks).
BYTES_PER_BLOCK = 2048
LOADINGS = ("settlement", "tilt")


@dataclass(frozen=True)
class GroundEdge:
    """The top edge of a support segment on a continuous ground, and the ground's motion at its two ends per
    unit settlement parameter: downward rate and horizontal motion (x positive)."""

    x: tuple[float, float]
    y: float
    down: tuple[float, float]
    horizontal: tuple[float, float]


@dataclass(frozen=True)
class Support:
    """How one support block moves: ``kind`` fixed or moving; ``motion`` translation, rotation (about
    ``pivot``) or ground (its top edge follows ``ground``); ``extent`` ``(start, end)`` [m] along the base for a
    support laid under a range of it (a spec's ``[supports.*]``, a profile's segment), else None.

    A translating or rotating support moves ``rate`` times as fast as the settlement parameter.
    """

    name: str
    kind: str = "fixed"
    motion: str = "none"
    pivot: tuple[float, float] | None = None
    rate: float = 1.0
    ground: GroundEdge | None = None
    direction: tuple[float, float] = (0.0, -1.0)  # of a translation, a unit vector
    extent: tuple[float, float] | None = None


def rotation_direction(centre, pivot) -> np.ndarray:
    """Dof-space motion of the small rotation about ``pivot`` that moves ``centre`` down by 1: the
    settlement parameter is the settlement of the support's centroid."""
    dx, dy = centre[0] - pivot[0], centre[1] - pivot[1]
    omega = -1.0 / dx
    return np.array([-omega * dy, omega * dx, omega])


def ground_direction(edge: GroundEdge, centre) -> np.ndarray:
    """Dof-space motion (ux, uy, rz) at ``centre`` per unit settlement of the rigid block whose top edge
    follows the ground: vertical motion linear between the ends' (so neighbouring segments meet at their
    common end), horizontal motion of the edge the mean of its ends' (a rigid edge cannot stretch), small
    rotation ``(down_a - down_b) / (x_b - x_a)``."""
    (xa, xb), (da, db) = edge.x, edge.down
    theta = (da - db) / (xb - xa)
    uy = -da + theta * (centre[0] - xa)
    ux = 0.5 * (edge.horizontal[0] + edge.horizontal[1]) + theta * (edge.y - centre[1])
    return np.array([ux, uy, theta])


def support_kinematics(supports, centres, loading: str):
    """``block_fixed``, ``settlement_direction`` and role of every support block (tilt: all held)."""
    count = len(supports)
    fixed = np.ones((count, 3), dtype=np.int8)
    direction = np.zeros((count, 3))
    roles = np.full(count, ROLE["fixed_support"], dtype=np.int8)
    if loading == "tilt":
        return fixed, direction, roles
    for i, support in enumerate(supports):
        if support.kind != "moving":
            continue
        roles[i] = ROLE["moving_support"]
        if support.motion == "rotation":
            fixed[i] = 0
            direction[i] = support.rate * rotation_direction(centres[i], support.pivot)
        elif support.motion == "ground":
            fixed[i] = 0
            direction[i] = ground_direction(support.ground, centres[i])
        else:
            dx, dy = support.direction
            fixed[i] = (dx == 0, dy == 0, 1)
            direction[i] = (support.rate * dx, support.rate * dy, 0.0)
    return fixed, direction, roles


def interface_kinds(blocks, ix, iy, is_support) -> np.ndarray:
    """``bed``, ``head``, ``support`` or ``other`` of every interface."""
    kind = flags("interface_kind")
    dx = np.abs(ix[:, 1] - ix[:, 0])
    dy = np.abs(iy[:, 1] - iy[:, 0])
    length = np.hypot(dx, dy)
    out = np.full(blocks.shape[0], kind["other"], dtype=np.int8)
    out[dy <= KIND_TOLERANCE * length] = kind["bed"]
    out[dx <= KIND_TOLERANCE * length] = kind["head"]
    out[is_support[blocks].any(axis=1)] = kind["support"]
    return out


def support_contact(blocks, length, support_index: np.ndarray, n_support: int) -> np.ndarray:
    """Wall-on-support contact length of every support (``support_index``: block -> support, -1 off supports)."""
    local = support_index[blocks]
    on = local >= 0
    return np.bincount(local[on], weights=np.broadcast_to(length[:, None], blocks.shape)[on], minlength=n_support)


def live_direction(support: Support) -> tuple[float, float]:
    """The unit direction of a moving support's live load: along its translation (down by default); a turning
    support and a ground segment settle, their live load points down."""
    return support.direction if support.motion == "translation" else (0.0, -1.0)


def carried_weight(weight_total: float, contact: np.ndarray, moving: np.ndarray) -> np.ndarray:
    """The paper's support loads: the masonry's weight ``W`` spread uniformly over its contact with all the
    supports (lengths in 2D, areas in 3D), so a moving support of contact ``L_m`` carries ``W L_m / L_total``
    (up as dead load, the same along its motion as live load); fixed supports carry none (0)."""
    total = contact.sum()
    if total <= 0:
        raise SpecError("supports: no masonry rests on any support")
    return np.where(moving, weight_total * contact / total, 0.0)


def support_reactions(supports, contact: np.ndarray, weight_total: float, loading: str) -> np.ndarray:
    """Dead-load reaction ``R = W L_m / L_total`` of every support (:func:`carried_weight`; none under tilt); a
    moving support on which no masonry rests is refused."""
    moving = np.array([loading == "settlement" and s.kind == "moving" for s in supports], dtype=bool)
    for support, length, carries in zip(supports, contact, moving):
        if carries and length <= 0:
            raise SpecError(f"{support.name}: no masonry rests on this moving support")
    return carried_weight(weight_total, contact, moving)


def support_loads(supports, reaction: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(support, 3)`` dead and live loads of the support blocks that carry ``reaction``: up, and along each
    one's :func:`live_direction`."""
    dead = np.zeros((len(supports), 3))
    live = np.zeros((len(supports), 3))
    dead[:, 1] = reaction
    live[:, :2] = reaction[:, None] * np.array([live_direction(s) for s in supports]).reshape(-1, 2)
    return dead, live


def model_from_blocks(
    node_x: np.ndarray,
    node_y: np.ndarray,
    block_node_count: np.ndarray,
    role: np.ndarray,
    thickness: np.ndarray | float,
    material: Material,
    supports,
    loading: str = "settlement",
    tilt_direction: int = 1,
    attrs: dict | None = None,
) -> xr.Dataset:
    """The model dataset of a block assembly (not yet checked: see :func:`masonryfw.checked_model`).

    ``role`` gives every block's flag (unit, lintel, fixed_support or
    moving_support, as in the format); ``supports`` describes the support
    blocks in block order, one :class:`Support` each. Polygons are counter-clockwise,
    in metres. ``attrs`` adds global attributes (``title``, ``source_spec``, ...).
    """
    if loading not in LOADINGS:
        raise SpecError(f"loading {loading!r}: must be one of {', '.join(LOADINGS)}")
    role = np.asarray(role, dtype=np.int8)
    node_x, node_y = np.asarray(node_x, dtype=float), np.asarray(node_y, dtype=float)
    counts = np.asarray(block_node_count, dtype=np.int32)
    is_support = support_blocks(role)
    supported = np.flatnonzero(is_support)
    if len(supports) != supported.size:
        raise SpecError(f"{supported.size} support blocks but {len(supports)} support descriptions")
    n_block = role.size
    area, cx, cy = polygon_area_centroid(node_x, node_y, counts)
    s_fixed, s_direction, s_role = support_kinematics(supports, np.c_[cx, cy][supported], loading)
    role = role.copy()
    role[supported] = s_role

    found = detect_interfaces(node_x, node_y, counts)
    blocks = np.asarray(found["blocks"], dtype=np.int64).reshape(-1, 2)
    keep = ~is_support[blocks].all(axis=1)
    blocks = blocks[keep]
    ix = np.asarray(found["x"], dtype=float).reshape(-1, 2)[keep]
    iy = np.asarray(found["y"], dtype=float).reshape(-1, 2)[keep]
    length = np.hypot(ix[:, 1] - ix[:, 0], iy[:, 1] - iy[:, 0])

    thickness = np.broadcast_to(np.asarray(thickness, dtype=float), (n_block,)).copy()
    unit_weight = np.where(is_support, 0.0, material.unit_weight)
    weight = unit_weight * np.abs(area) * thickness
    support_index = np.full(n_block, -1)
    support_index[supported] = np.arange(supported.size)
    contact = support_contact(blocks, length, support_index, supported.size)
    reaction = support_reactions(supports, contact, weight.sum(), loading)

    dead = np.zeros((n_block, 3))
    live = np.zeros((n_block, 3))
    dead[:, 1] = -weight
    dead[supported], live[supported] = support_loads(supports, reaction)
    if loading == "tilt":
        live[~is_support, 0] = tilt_direction * weight[~is_support]
    fixed = np.zeros((n_block, 3), dtype=np.int8)
    fixed[supported] = s_fixed
    direction = np.zeros((n_block, 3))
    direction[supported] = s_direction

    n_interface = blocks.shape[0]
    variables = {
        "node_x": (("node",), node_x),
        "node_y": (("node",), node_y),
        "block_node_count": (("block",), counts),
        "block_geometry": ((), np.int8(0)),
        "block_role": (("block",), role),
        "block_thickness": (("block",), thickness),
        "block_unit_weight": (("block",), unit_weight),
        "interface_blocks": (("interface", "side"), blocks.astype(np.int32)),
        "interface_x": (("interface", "end"), ix),
        "interface_y": (("interface", "end"), iy),
        "interface_kind": (("interface",), interface_kinds(blocks, ix, iy, is_support)),
        "interface_friction": (("interface",), np.full(n_interface, material.friction)),
        "interface_cohesion": (("interface",), np.full(n_interface, material.cohesion)),
        "interface_tensile_strength": (("interface",), np.full(n_interface, material.tensile_strength)),
        "block_fixed": (("block", "dof"), fixed),
        "settlement_direction": (("block", "dof"), direction),
    }
    if material.young_modulus is not None:
        variables["block_young_modulus"] = (("block",), np.full(n_block, material.young_modulus))
    if material.poisson_ratio is not None:
        variables["block_poisson_ratio"] = (("block",), np.full(n_block, material.poisson_ratio))
    data_vars = {name: (dims, values, variable_attrs(name)) for name, (dims, values) in variables.items()}
    data_vars.update(load_variables("dead", dead))
    data_vars.update(load_variables("live", live))
    return xr.Dataset(
        data_vars,
        coords={"dof": ("dof", list(DOF_NAMES), variable_attrs("dof"))},
        attrs={**format_header("model"), "title": "", **(attrs or {})},
    )


def with_supports(model: xr.Dataset, supports) -> xr.Dataset:
    """``model`` under the settlement loading with its support blocks (in block order) moving as ``supports``
    say: their roles, held components, settlement directions and the paper's dead and live loads made anew,
    every other variable kept (the geometry, the interfaces, the masonry's weight). Cheaper than building the
    model again: a settlement diagnosis tries hundreds of profiles on one wall."""
    role = model.block_role.values.copy()
    supported = np.flatnonzero(support_blocks(role))
    if len(supports) != supported.size:
        raise SpecError(f"{supported.size} support blocks but {len(supports)} support descriptions")
    centres = np.c_[model.block_centroid_x.values, model.block_centroid_y.values][supported]
    s_fixed, s_direction, role[supported] = support_kinematics(supports, centres, "settlement")
    support_index = np.full(role.size, -1)
    support_index[supported] = np.arange(supported.size)
    contact = support_contact(model.interface_blocks.values.astype(np.int64), model.interface_length.values,
                              support_index, supported.size)
    dead = block_loads(model, "dead").copy()
    masonry = np.ones(role.size, dtype=bool)
    masonry[supported] = False
    live = np.zeros_like(dead)
    dead[supported], live[supported] = support_loads(supports, support_reactions(supports, contact,
                                                                                -dead[masonry, 1].sum(),
                                                                                "settlement"))
    fixed = model.block_fixed.values.copy()
    fixed[supported] = s_fixed
    direction = np.zeros((role.size, 3))
    direction[supported] = s_direction
    return model.assign({
        "block_role": model.block_role.copy(data=role),
        "block_fixed": model.block_fixed.copy(data=fixed),
        "settlement_direction": model.settlement_direction.copy(data=direction),
        **{name: (dims, values, model[name].attrs) for name, (dims, values, _) in
           {**load_variables("dead", dead), **load_variables("live", live)}.items()},
    })


def rectangle_nodes(x0, x1, y0, y1):
    """Counter-clockwise vertices ``(node_x, node_y, block_node_count)`` of rectangles, block after block."""
    node_x = np.stack((x0, x1, x1, x0), axis=1).ravel()
    node_y = np.stack((y0, y0, y1, y1), axis=1).ravel()
    return node_x, node_y, np.full(np.size(x0), 4, dtype=np.int32)
