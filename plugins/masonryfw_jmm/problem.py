"""From a model and the options to a non-dimensional FE problem: mesh, materials, supports, loads.

Scales: lengths by the masonry height H, stresses by S = gamma H (gamma: the largest
masonry unit weight), displacements by U = S H / G (G: the units' shear modulus), forces
by S H^2 (thickness t enters as t / H). In these units G = 1, gravity is 1 and the
displacements of the gravity stage are of order 1.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import xarray as xr
from skfem import MeshTri

import masonryfw as mf
import masonryfw.plugin_api as mfp

from .fabric import bed_angles, extents_along, head_joints, stress_rotation
from .fem import Discretisation
from .material import JointStrength, ReturnMap, elastic_matrix
from .mesh import WallMesh, block_boxes, masonry, wall_mesh

ROLE = mfp.ROLE
KIND = mfp.flags("interface_kind")


@dataclass
class Problem:
    """Everything the incremental solver needs, non-dimensional."""

    mesh: WallMesh
    disc: Discretisation
    return_map: ReturnMap
    masonry_points: np.ndarray  # bool (points,): plastic JMM material; False = elastic lintel
    D_points: np.ndarray  # (points, 3, 3) elastic matrices
    gravity: np.ndarray  # (ndof,) body force at full gravity
    fixed: np.ndarray  # prescribed DOFs held at zero
    moving: np.ndarray  # prescribed DOFs that move with the support
    moving_direction: np.ndarray  # (moving,) displacement of each moving DOF per unit settlement
    moving_weight: np.ndarray  # (moving,) settlement weight: the reaction is -sum(residual[moving] * weight)
    support_uy: np.ndarray  # vertical DOFs of every support (fixed and moving)
    support_of: np.ndarray  # (support_uy,) the support block each belongs to
    length: float  # H [m]
    mesh_size: float  # [m]
    stress: float  # S [Pa]
    displacement: float  # U [m]
    force: float  # S H^2 [N]
    beta: float
    young: float
    poisson: float
    strength: JointStrength
    live: np.ndarray | None = None  # (ndof,) body force of the live load at load factor 1
    to_bed: np.ndarray | None = None  # (masonry points, 3, 3) stresses into each point's bed frame; None: horizontal
    from_bed: np.ndarray | None = None  # the inverse rotations
    face_bounds: np.ndarray | None = None  # (faces, masonry points) b per point (no head faces without head joints)
    searches_load: bool = False  # no moving support: the live load's factor grows instead of a settlement
    n_block: int = 0  # blocks of the model (the per-support reactions are per block)

    @cached_property
    def compliance(self) -> np.ndarray:
        """``(points, 3, 3)`` inverses of ``D_points`` (the elastic strain of a stress), computed once."""
        return np.linalg.inv(self.D_points)

    def settlement_reaction(self, nodal_force: np.ndarray) -> float:
        """The settlement reaction of nodal forces on the wall (``mf.settlement_reaction``, non-dimensional)."""
        return -float(nodal_force[self.moving] @ self.moving_weight)

    @property
    def free(self) -> np.ndarray:
        mask = np.ones(self.disc.ndof, dtype=bool)
        mask[self.fixed] = False
        mask[self.moving] = False
        return np.nonzero(mask)[0]


def _modal(values: np.ndarray, tol: float) -> float:
    """The most frequent value of ``values`` (grouped to ``tol``; the mean of that group)."""
    groups = np.round(values / tol)
    keys, counts = np.unique(groups, return_counts=True)
    return float(values[groups == keys[counts.argmax()]].mean())


def unit_size(model: xr.Dataset, angles: np.ndarray) -> tuple[float, float]:
    """``(b, a)``: length and height of the commonest unit, measured along and across its bed direction."""
    units = mfp.jointed_blocks(model.block_role.values)
    if not units.any():
        raise mf.ModelError("jmm: no unit blocks to take the unit size b x a from; give options beta and mesh_size")
    length, height = extents_along(model, angles)
    tol = 1e-6 * mfp.model_scale(model.node_x.values, model.node_y.values)
    return _modal(length[units], tol), _modal(height[units], tol)


def median_unit_height(model: xr.Dataset, angles: np.ndarray) -> float:
    """The median extent of the units across their beds: half of it is the automatic mesh size (the
    commonest unit's height in a wall of courses; the voussoirs' widths in an arch on piers of fewer units)."""
    units = mfp.jointed_blocks(model.block_role.values)
    return float(np.median(extents_along(model, angles)[1][units]))


def interlocking_beta(model: xr.Dataset, friction_bed: float, angles: np.ndarray) -> float:
    """beta = tan(phi_bed) b / (2 a) (eq. 13), b and a the length and height of the commonest unit.

    With mu = 0.4: 200 x 50 mm units give 0.4 * 200 / 100 = 0.8 (Tests 8C, 12C), 100 x 50 mm
    units give 0.4 (the others), the paper's values.
    """
    b, a = unit_size(model, angles)
    return friction_bed * b / (2.0 * a)


def joint_planes(model: xr.Dataset, angles: np.ndarray) -> np.ndarray:
    """``(interface,)`` ``"bed"``, ``"head"`` or ``""``: a joint between masonry blocks is a bed joint when it
    runs within 45 deg of its side-0 block's bed direction (the interface kind in a wall of courses);
    a joint on a support is neither."""
    sides = model.interface_blocks.values.astype(np.int64)
    on_support = mfp.support_blocks(model.block_role.values)[sides].any(axis=1)
    direction = np.arctan2(np.diff(model.interface_y.values, axis=1)[:, 0], np.diff(model.interface_x.values, axis=1)[:, 0])
    off = np.abs(np.sin(direction - angles[sides[:, 0]]))
    return np.where(on_support, "", np.where(off < np.sqrt(0.5), "bed", "head"))


def _joint_mean(model: xr.Dataset, name: str, planes: np.ndarray, plane: str, fallback: str) -> float:
    """Mean of interface variable ``name`` over the joints of ``plane``, else of ``fallback``, else (masonry
    that stands on its supports alone) over every joint."""
    for chosen in (planes == plane, planes == fallback, np.ones(planes.size, dtype=bool)):
        if chosen.any():
            return float(model[name].values[chosen].mean())
    raise mf.ModelError(f"jmm: the model has no interfaces to take {name} from")


def _block_constant(model: xr.Dataset, name: str, blocks: np.ndarray, option: float | None,
                    default: float) -> np.ndarray:
    """Per-block constant: the option if given, else the model's variable, else ``default``."""
    if option is not None:
        return np.full(blocks.size, option)
    if name in model:
        return model[name].values[blocks].astype(float)
    return np.full(blocks.size, default)


def strength_from_model(model: xr.Dataset, beta: float | None, dilatancy: float | None,
                        angles: np.ndarray) -> tuple[JointStrength, float]:
    """The JMM strength (physical units) from the bed and head joints (:func:`joint_planes`); and beta
    (auto: eq. 13). ``dilatancy``: the dilatancy angle psi [deg] of both planes, None for associated flow.
    """
    planes = joint_planes(model, angles)
    mu_bed = _joint_mean(model, "interface_friction", planes, "bed", "head")
    mu_head = _joint_mean(model, "interface_friction", planes, "head", "bed")
    beta = beta if beta is not None else interlocking_beta(model, mu_bed, angles)
    tan_psi = None if dilatancy is None else float(np.tan(np.radians(dilatancy)))
    strength = JointStrength(
        friction_bed=mu_bed, friction_head=mu_head,
        cohesion_bed=_joint_mean(model, "interface_cohesion", planes, "bed", "head"),
        cohesion_head=_joint_mean(model, "interface_cohesion", planes, "head", "bed"),
        tensile_bed=_joint_mean(model, "interface_tensile_strength", planes, "bed", "head"),
        tensile_head=_joint_mean(model, "interface_tensile_strength", planes, "head", "bed"),
        beta=beta, dilatancy_bed=tan_psi, dilatancy_head=tan_psi,
    )
    return strength, beta


def regularised(strength: JointStrength, shift: float) -> JointStrength:
    """The strength with both planes' Coulomb apexes moved ``shift`` into tension (cohesion shift tan(phi)).

    With the paper's c = sigma_t = 0 the stress-free boundary (sigma_n = tau = 0 on the
    top surface and at openings) lies exactly on the apex, and points there flip between
    elastic and yielding from one iteration to the next, so Newton stalls. A cohesion
    ``shift tan(phi)`` (non-dimensional: ``shift`` times gamma H) puts those points strictly
    inside; the cut-off stays at or beyond the moved apex, so it is still dropped. The
    effect on the reaction is of order ``shift tan(phi)`` relative (tests and docs/jmm.md).
    """
    if shift <= 0:
        return strength
    return JointStrength(
        strength.friction_bed, strength.friction_head,
        strength.cohesion_bed + shift * strength.friction_bed,
        strength.cohesion_head + shift * strength.friction_head,
        strength.tensile_bed + shift, strength.tensile_head + shift,
        strength.beta, strength.dilatancy_bed, strength.dilatancy_head,
    )


def support_facets(points: np.ndarray, ends: np.ndarray, segments: np.ndarray, tol: float) -> np.ndarray:
    """``(facets,)`` index of the support segment each facet lies on (both ends within ``tol``), -1 if none.

    ``ends``: ``(2, facets)`` node indices; ``segments``: ``(k, end, xy)``, in the units of ``points``.
    """
    px, py = points[0, ends], points[1, ends]  # (2 ends, facets)
    ax, ay = segments[:, 0, 0], segments[:, 0, 1]
    bx, by = segments[:, 1, 0], segments[:, 1, 1]
    near = np.ones((ends.shape[1], segments.shape[0]), dtype=bool)
    for end in (0, 1):
        near &= mfp.point_segment_distance(px[end][:, None], py[end][:, None], ax, ay, bx, by) <= tol
    return np.where(near.any(axis=1), near.argmax(axis=1), -1)


def _support_dofs(mesh: WallMesh, disc: Discretisation, model: xr.Dataset, length: float, tol: float):
    """Fixed DOFs, moving DOFs and their motion per unit settlement, from the support segments (the masonry
    on its supports); the moving arrays are empty when no support moves. Last, the vertical prescribed DOFs
    and the support block each belongs to (a node two supports share goes to the fixed one)."""
    m = disc.mesh
    boundary = m.boundary_facets()
    on = support_facets(m.p, m.facets[:, boundary], mesh.supports / length, tol)
    locs = disc.basis.doflocs
    block = np.where(on >= 0, mesh.support_block[np.maximum(on, 0)], -1)
    fixed, moving, direction, vertical = [], [], [], []
    for support in np.unique(block[block >= 0]):  # a handful of supports
        dofs = disc.facet_dofs(boundary[block == support])
        is_fixed = mfp.fixed_blocks(model.block_role.values[support])
        vertical.append((not is_fixed, 2 * dofs + 1, np.full(dofs.size, support)))
        if is_fixed:
            fixed.append(np.concatenate([2 * dofs, 2 * dofs + 1]))
            continue
        d = model.settlement_direction.values[support]
        cx, cy = (model[f"block_centroid_{c}"].values[support] / length for c in "xy")
        ux = d[0] - d[2] * length * (locs[1, dofs] - cy)
        uy = d[1] + d[2] * length * (locs[0, dofs] - cx)
        moving.append(np.concatenate([2 * dofs, 2 * dofs + 1]))
        direction.append(np.concatenate([ux, uy]))
    if not fixed and not moving:
        lengths = np.hypot(*(mesh.supports[:, 1] - mesh.supports[:, 0]).T)
        if lengths.size == 0:
            raise mf.ModelError("jmm: the model has no interface between masonry and a support: the wall stands "
                                "on nothing")
        raise mf.ModelError(f"jmm: no edge of the {mesh.mesher} mesh lies on any of the {lengths.size} support "
                            f"interfaces ({lengths.min():.4g} to {lengths.max():.4g} m long); a mesh_size of at "
                            f"most {lengths.min():.4g} m puts nodes on every one")
    fixed = np.unique(np.concatenate(fixed)) if fixed else np.zeros(0, int)
    vertical.sort(key=lambda entry: entry[0])  # fixed supports first: they keep shared nodes
    uy, first = np.unique(np.concatenate([dofs for _, dofs, _ in vertical]), return_index=True)
    owner = np.concatenate([owners for _, _, owners in vertical])[first]
    if not moving:
        return fixed, np.zeros(0, int), np.zeros(0), uy, owner
    moving = np.concatenate(moving)
    direction = np.concatenate(direction)
    keep = ~np.isin(moving, fixed)  # a node shared with a fixed support stays fixed
    moving, direction = moving[keep], direction[keep]
    moving, first = np.unique(moving, return_index=True)
    return fixed, moving, direction[first], uy, owner


def _elastic_matrices(young: np.ndarray, poisson: np.ndarray, hypothesis: str) -> np.ndarray:
    """``(n, 3, 3)`` elastic matrices, one per distinct (E, nu) pair."""
    pairs, which = np.unique(np.stack([young, poisson], axis=1), axis=0, return_inverse=True)
    return np.stack([elastic_matrix(e, n, hypothesis) for e, n in pairs])[which.ravel()]


@dataclass(frozen=True)
class Domain:
    """What both methods need: the wall meshed, its scales and its joint strength (physical units)."""

    mesh: WallMesh
    length: float  # H [m]: masonry height
    mesh_size: float  # [m]
    stress: float  # S = gamma H [Pa]
    force: float  # S H^2 [N]
    unit_weight: float  # gamma [N m-3]: the largest masonry unit weight
    strength: JointStrength
    beta: float
    angles: np.ndarray  # (block,) bed direction [rad] (fabric.py)
    headless: np.ndarray  # (block,) no head joints: the bed faces only (fabric.py)

    def scaled_strength(self, apex_shift: float) -> JointStrength:
        """The non-dimensional strength (stresses over S) with the apex regularisation."""
        return regularised(self.strength.scaled(self.stress), apex_shift)


def masonry_height(model: xr.Dataset) -> float:
    box = block_boxes(model)[masonry(model)]
    return float(box[:, 3].max() - box[:, 1].min())


def auto_mesh_size(model: xr.Dataset) -> float:
    """The ``mesh_size`` option's automatic value: half the median unit height (a tenth of the masonry height
    without units)."""
    if mfp.jointed_blocks(model.block_role.values).any():
        return median_unit_height(model, bed_angles(model)) / 2
    return masonry_height(model) / 20


def wall_domain(model: xr.Dataset, mesh_size: float | None, beta: float | None,
                dilatancy: float | None = None) -> Domain:
    """Mesh the wall (cells no larger than ``mesh_size``, auto: half the unit height), scale it, read its strength."""
    H = masonry_height(model)
    angles = bed_angles(model)
    size = mesh_size if mesh_size is not None else auto_mesh_size(model)
    mesh = wall_mesh(model, size)
    gamma_ref = float(model.block_unit_weight.values[mesh.block].max())
    if not gamma_ref > 0:
        raise mf.ModelError("jmm: the masonry has no weight (block_unit_weight is 0 everywhere)")
    strength, beta = strength_from_model(model, beta, dilatancy, angles)
    S = gamma_ref * H
    return Domain(mesh, H, size, S, S * H * H, gamma_ref, strength, beta, angles, ~head_joints(model, angles))


def live_body_force(model: xr.Dataset, blocks: np.ndarray, unit_weight: float) -> np.ndarray:
    """``(triangles, 2)`` the live load of every masonry block spread uniformly over its volume, over
    ``unit_weight`` (the non-dimensional body force); a live moment has no such meaning and is refused."""
    live = mfp.block_loads(model, "live")
    moment = np.flatnonzero(live[blocks, 2] != 0)
    if moment.size:
        raise mf.ModelError(f"block(s) {mfp.listed(np.unique(blocks[moment]))}: live_load has a moment; jmm "
                            "spreads a block's live load over its volume, which carries forces only")
    volume = model.block_area.values * model.block_thickness.values
    return live[blocks, :2] / volume[blocks, None] / unit_weight


#: The bound of a face a point does not have: never reached by non-dimensional stresses (of order 1).
ABSENT_FACE = 1e6


def headless_bounds(rmap: ReturnMap, headless: np.ndarray) -> np.ndarray | None:
    """``(faces, points)`` bounds with the head faces lifted out of reach at ``headless`` points (None if none)."""
    if not headless.any():
        return None
    bounds = np.repeat(rmap.b[:, None], headless.size, axis=1)
    head = np.array([name.startswith("head") for name in rmap.names])
    bounds[np.ix_(head, headless)] = ABSENT_FACE
    return bounds


def bed_rotations(angle: np.ndarray) -> tuple[np.ndarray | None, np.ndarray | None]:
    """``(to bed, from bed)`` Voigt rotations of the points, or ``(None, None)`` when every bed is horizontal."""
    if not np.any(angle):
        return None, None
    return stress_rotation(angle), stress_rotation(-angle)


def build_problem(model: xr.Dataset, options) -> Problem:
    """Mesh the wall and set up materials, supports and gravity for the incremental method."""
    domain = wall_domain(model, options["mesh_size"], options["beta"], options["dilatancy"])
    mesh, H, size, S = domain.mesh, domain.length, domain.mesh_size, domain.stress
    role = model.block_role.values
    blocks = mesh.block
    nu = _block_constant(model, "block_poisson_ratio", blocks, options["poisson_ratio"], 0.2)
    if options["shear_modulus"] is not None:
        E = 2.0 * options["shear_modulus"] * (1.0 + nu)
    else:  # the model's E, else the paper's G = 511 MPa
        E = _block_constant(model, "block_young_modulus", blocks, None, 0.0)
        E = np.where(E > 0, E, 2.0 * 511e6 * (1.0 + nu))
    is_unit = mfp.jointed_blocks(role[blocks])
    ref = is_unit if is_unit.any() else np.ones_like(is_unit)
    young, poisson = float(E[ref].mean()), float(nu[ref].mean())
    G = young / (2.0 * (1.0 + poisson))
    gamma = model.block_unit_weight.values[blocks].astype(float)
    U = S * H / G
    thickness = model.block_thickness.values[blocks] / H
    disc = Discretisation(MeshTri(mesh.points / H, mesh.triangles), options["element"], thickness)
    D_points = np.repeat(_elastic_matrices(E / G, nu, options["hypothesis"]), disc.nqp, axis=0)
    masonry_points = np.repeat(mfp.jointed_blocks(role[blocks]), disc.nqp)
    rmap = ReturnMap(domain.scaled_strength(options["apex_shift"]),
                     elastic_matrix(young / G, poisson, options["hypothesis"]))
    body = np.stack([np.zeros(blocks.size), -gamma / domain.unit_weight], axis=1)
    gravity = disc.body_force(body)
    fixed, moving, direction, support_uy, support_of = _support_dofs(mesh, disc, model, H, 1e-6 * size / H)
    searches_load = moving.size == 0
    if not searches_load:
        mfp.refuse_rigid_settlement(model, "jmm")
    if searches_load and not np.any(mfp.block_loads(model, "live")[masonry(model)]):
        raise mf.ModelError("jmm: no moving support to settle and no live load to raise: nothing to analyse")
    live = disc.body_force(live_body_force(model, blocks, domain.unit_weight))
    to_bed, from_bed = bed_rotations(np.repeat(domain.angles[blocks], disc.nqp)[masonry_points])
    face_bounds = headless_bounds(rmap, np.repeat(domain.headless[blocks], disc.nqp)[masonry_points])
    return Problem(
        mesh=mesh, disc=disc, return_map=rmap, masonry_points=masonry_points, D_points=D_points,
        gravity=gravity, fixed=fixed, moving=moving, moving_direction=direction,
        moving_weight=direction, support_uy=support_uy, support_of=support_of, length=H, mesh_size=size, stress=S, displacement=U, force=domain.force,
        beta=domain.beta, young=young, poisson=poisson, strength=domain.strength, live=live, to_bed=to_bed,
        from_bed=from_bed, face_bounds=face_bounds, searches_load=searches_load,
        n_block=model.sizes["block"],
    )
