"""From a model and the options to a non-dimensional FE problem: mesh, materials, supports, loads.

Scales: lengths by the masonry height H, stresses by S = gamma H (gamma: the largest
masonry unit weight), displacements by U = S H / G (G: the units' shear modulus), forces
by S H^2 (thickness t enters as t / H). In these units G = 1, gravity is 1 and the
displacements of the gravity stage are of order 1.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr
from skfem import MeshTri

import masonryfw as mf

from .fem import Discretisation
from .material import JointStrength, ReturnMap, elastic_matrix
from .mesh import WallMesh, block_rectangles, wall_mesh

ROLE = mf.flags("block_role")
KIND = mf.flags("interface_kind")


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
    moving_vertical: np.ndarray  # bool (moving,): uy DOFs (their reactions sum to the vertical reaction)
    length: float  # H [m]
    mesh_size: float  # [m]
    stress: float  # S [Pa]
    displacement: float  # U [m]
    force: float  # S H^2 [N]
    beta: float
    young: float
    poisson: float
    strength: JointStrength

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


def interlocking_beta(model: xr.Dataset, friction_bed: float) -> float:
    """beta = tan(phi_bed) b / (2 a) (eq. 13), b and a the length and height of the commonest unit.

    With mu = 0.4: 200 x 50 mm units give 0.4 * 200 / 100 = 0.8 (Tests 8C, 12C), 100 x 50 mm
    units give 0.4 (the others), the paper's values.
    """
    box = block_rectangles(model)
    units = model.block_role.values == ROLE["unit"]
    if not units.any():
        raise mf.ModelError("jmm: no unit blocks to take the unit size b x a for beta from; give option beta")
    tol = 1e-6 * mf.model_scale(model.node_x.values, model.node_y.values)
    b = _modal(box[units, 2] - box[units, 0], tol)
    a = _modal(box[units, 3] - box[units, 1], tol)
    return friction_bed * b / (2.0 * a)


def _joint_mean(model: xr.Dataset, name: str, kind: str, fallback: str | None = None) -> float:
    """Mean of interface variable ``name`` over joints of ``kind`` (else ``fallback`` kind)."""
    chosen = model.interface_kind.values == KIND[kind]
    if not chosen.any() and fallback is not None:
        return _joint_mean(model, name, fallback)
    if not chosen.any():
        raise mf.ModelError(f"jmm: the model has no {kind} interfaces to take {name} from")
    return float(model[name].values[chosen].mean())


def _block_constant(model: xr.Dataset, name: str, blocks: np.ndarray, option: float | None,
                    default: float) -> np.ndarray:
    """Per-block constant: the option if given, else the model's variable, else ``default``."""
    if option is not None:
        return np.full(blocks.size, option)
    if name in model:
        return model[name].values[blocks].astype(float)
    return np.full(blocks.size, default)


def strength_from_model(model: xr.Dataset, beta: float | None, dilatancy: float | None) -> tuple[JointStrength, float]:
    """The JMM strength (physical units) from the bed/head interfaces; and beta (auto: eq. 13).

    ``dilatancy``: the dilatancy angle psi [deg] of both planes, None for associated flow.
    """
    mu_bed = _joint_mean(model, "interface_friction", "bed")
    mu_head = _joint_mean(model, "interface_friction", "head", "bed")
    beta = beta if beta is not None else interlocking_beta(model, mu_bed)
    tan_psi = None if dilatancy is None else float(np.tan(np.radians(dilatancy)))
    strength = JointStrength(
        friction_bed=mu_bed, friction_head=mu_head,
        cohesion_bed=_joint_mean(model, "interface_cohesion", "bed"),
        cohesion_head=_joint_mean(model, "interface_cohesion", "head", "bed"),
        tensile_bed=_joint_mean(model, "interface_tensile_strength", "bed"),
        tensile_head=_joint_mean(model, "interface_tensile_strength", "head", "bed"),
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


def _support_dofs(mesh: WallMesh, disc: Discretisation, model: xr.Dataset, length: float, tol: float):
    """Fixed DOFs, moving DOFs and their motion per unit settlement, from the support blocks' top edges."""
    m = disc.mesh
    boundary = m.boundary_facets()
    mid = m.p[:, m.facets[:, boundary]].mean(axis=1)
    horizontal = np.isclose(m.p[1, m.facets[0, boundary]], m.p[1, m.facets[1, boundary]], atol=tol)
    locs = disc.basis.doflocs
    fixed, moving, direction = [], [], []
    for x0, x1, y, block, role in mesh.supports:  # a handful of supports
        x0, x1, y = x0 / length, x1 / length, y / length
        on = horizontal & np.isclose(mid[1], y, atol=tol) & (mid[0] > x0 - tol) & (mid[0] < x1 + tol)
        dofs = disc.facet_dofs(boundary[on])
        if role == ROLE["fixed_support"]:
            fixed.append(np.concatenate([2 * dofs, 2 * dofs + 1]))
            continue
        d = model.settlement_direction.values[block]
        cx, cy = (model[f"block_centroid_{c}"].values[block] / length for c in "xy")
        ux = d[0] - d[2] * length * (locs[1, dofs] - cy)
        uy = d[1] + d[2] * length * (locs[0, dofs] - cx)
        moving.append(np.concatenate([2 * dofs, 2 * dofs + 1]))
        direction.append(np.concatenate([ux, uy]))
    fixed = np.unique(np.concatenate(fixed)) if fixed else np.zeros(0, int)
    if not moving:
        raise mf.ModelError("jmm: the model has no moving_support block under the wall to settle")
    moving = np.concatenate(moving)
    direction = np.concatenate(direction)
    keep = ~np.isin(moving, fixed)  # a node shared with a fixed support stays fixed
    moving, direction = moving[keep], direction[keep]
    moving, first = np.unique(moving, return_index=True)
    if moving.size == 0:
        raise mf.ModelError("jmm: no mesh node lies on the moving support's top edge")
    return fixed, moving, direction[first]


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

    def scaled_strength(self, apex_shift: float) -> JointStrength:
        """The non-dimensional strength (stresses over S) with the apex regularisation."""
        return regularised(self.strength.scaled(self.stress), apex_shift)


def wall_domain(model: xr.Dataset, mesh_size: float | None, beta: float | None,
                dilatancy: float | None = None) -> Domain:
    """Mesh the wall (cells no larger than ``mesh_size``, auto: half the unit height), scale it, read its strength."""
    role = model.block_role.values
    masonry_blocks = np.isin(role, [ROLE["unit"], ROLE["lintel"]])
    box = block_rectangles(model)
    ys = box[masonry_blocks][:, [1, 3]]
    H = float(ys.max() - ys.min())
    unit_height = _modal(box[role == ROLE["unit"], 3] - box[role == ROLE["unit"], 1], 1e-6 * H) if (
        role == ROLE["unit"]).any() else H / 10
    size = mesh_size if mesh_size is not None else unit_height / 2
    mesh = wall_mesh(model, size)
    gamma_ref = float(model.block_unit_weight.values[mesh.block].max())
    if not gamma_ref > 0:
        raise mf.ModelError("jmm: the masonry has no weight (block_unit_weight is 0 everywhere)")
    strength, beta = strength_from_model(model, beta, dilatancy)
    S = gamma_ref * H
    return Domain(mesh, H, size, S, S * H * H, gamma_ref, strength, beta)


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
    is_unit = role[blocks] == ROLE["unit"]
    ref = is_unit if is_unit.any() else np.ones_like(is_unit)
    young, poisson = float(E[ref].mean()), float(nu[ref].mean())
    G = young / (2.0 * (1.0 + poisson))
    gamma = model.block_unit_weight.values[blocks].astype(float)
    U = S * H / G
    thickness = model.block_thickness.values[blocks] / H
    disc = Discretisation(MeshTri(mesh.points / H, mesh.triangles), options["element"], thickness)
    D_points = np.repeat(_elastic_matrices(E / G, nu, options["hypothesis"]), disc.nqp, axis=0)
    masonry_points = np.repeat(role[blocks] == ROLE["unit"], disc.nqp)
    rmap = ReturnMap(domain.scaled_strength(options["apex_shift"]),
                     elastic_matrix(young / G, poisson, options["hypothesis"]))
    body = np.stack([np.zeros(blocks.size), -gamma / domain.unit_weight], axis=1)
    gravity = disc.body_force(body)
    fixed, moving, direction = _support_dofs(mesh, disc, model, H, 1e-6 * size / H)
    return Problem(
        mesh=mesh, disc=disc, return_map=rmap, masonry_points=masonry_points, D_points=D_points,
        gravity=gravity, fixed=fixed, moving=moving, moving_direction=direction,
        moving_vertical=moving % 2 == 1, length=H, mesh_size=size, stress=S, displacement=U, force=domain.force,
        beta=domain.beta, young=young, poisson=poisson, strength=domain.strength,
    )
