"""The ground under a wall as support segments that a settlement profile moves: cut once, moved many times.

A ``[settlement]`` profile (:mod:`masonryfw.ground.profiles`) moves the ground under a wall; the ground itself
is a set of support blocks, the pieces of the ground areas (drawn ground blocks, or a ground one median
block high made under the masonry's lowest edges) cut by the vertical strips of the segment grid. Only the
pieces that carry masonry are kept. :func:`ground_model` builds a wall on such a ground once, every
segment held; :func:`over_profile` moves its segments as a profile says, keeping the geometry and the
interfaces: what a settlement diagnosis does hundreds of times.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..format.derived import derive_geometry
from ..format.roles import ROLE, masonry_blocks, support_blocks
from ..geometry.polygons import block_bounds
from ..ground.profiles import Profile, node_motion, segment_count, with_profile
from ..readers.material import Material
from ..runtime.errors import SpecError
from . import blocks

if TYPE_CHECKING:  # annotations only
    import xarray as xr



def polygons(node_x: np.ndarray, node_y: np.ndarray, counts: np.ndarray):
    """Shapely polygons of ragged blocks."""
    import shapely

    return shapely.polygons(shapely.linearrings(np.c_[node_x, node_y],
                                                indices=np.repeat(np.arange(counts.size), counts)))


def made_ground(node_x: np.ndarray, node_y: np.ndarray, counts: np.ndarray, masonry: np.ndarray):
    """A ground one median block high under the masonry's lowest edges, across its width (a shapely box)."""
    import shapely

    xmin, xmax, ymin, ymax = block_bounds(node_x, node_y, counts)
    base = float(ymin[masonry].min())
    depth = float(np.median(ymax[masonry] - ymin[masonry]))
    return shapely.box(float(xmin[masonry].min()), base - depth, float(xmax[masonry].max()), base)


def ground_pieces(areas, carried, edges: np.ndarray, tol: float) -> list[tuple]:
    """``(polygon, segment index)`` of every piece of the ground ``areas`` between consecutive ``edges`` that
    shares more than ``tol`` of its outline with the masonry outline ``carried`` (pieces under nothing go)."""
    import shapely

    bounds = shapely.bounds(areas)
    low, high = float(bounds[:, 1].min()) - 1.0, float(bounds[:, 3].max()) + 1.0
    pieces = []
    for k, (a, b) in enumerate(zip(edges[:-1], edges[1:])):
        strip = shapely.box(float(a), low, float(b), high)
        for area in areas:
            for piece in shapely.get_parts(shapely.intersection(area, strip)):
                if piece.geom_type == "Polygon" and shapely.length(shapely.intersection(piece.boundary, carried)) > tol:
                    pieces.append((shapely.orient_polygons(piece), k))
    return pieces


def masonry_material(model: xr.Dataset) -> Material:
    """The material of a model's masonry, its median unit weight and joint strengths."""
    masonry = masonry_blocks(model.block_role.values)
    return Material(
        unit_weight=float(np.median(model.block_unit_weight.values[masonry])),
        friction=float(np.median(model.interface_friction.values)),
        cohesion=float(np.median(model.interface_cohesion.values)),
        tensile_strength=float(np.median(model.interface_tensile_strength.values)),
        young_modulus=float(np.median(model.block_young_modulus.values[masonry])) if "block_young_modulus" in model
        else None,
        poisson_ratio=float(np.median(model.block_poisson_ratio.values[masonry])) if "block_poisson_ratio" in model
        else None,
    )


def ground_model(model: xr.Dataset, segment: float, key: str = "segment") -> xr.Dataset:
    """The masonry of ``model`` (its units and lintels; its support kinematics, loads and any profile set aside)
    on its ground cut into vertical strips about ``segment`` long [m], every piece a held support, with its derived
    geometry (not checked: with every segment held it has no live load; a profile makes it whole,
    :func:`over_profile`). The ground is the model's support blocks (the drawn base, a spec's supports), or
    one made under the lowest masonry edges for a model without any. Refused for a wall with no masonry
    resting on that ground, and for a ``segment`` that leaves fewer than two pieces or is finer than a hundredth of
    the median unit length (:func:`masonryfw.ground.profiles.segment_count`; ``key`` names the segment in the message)."""
    import shapely

    role = model.block_role.values
    masonry = masonry_blocks(role)
    if not masonry.any():
        raise SpecError("the model has no masonry (units or lintels) to put on a ground")
    counts_all = model.block_node_count.values.astype(np.int64)
    keep = np.repeat(masonry, counts_all)
    node_x, node_y = model.node_x.values[keep], model.node_y.values[keep]
    counts = counts_all[masonry].astype(np.int32)
    supports = support_blocks(role)
    if supports.any():  # merged first: the segment grid alone cuts the ground
        merged = shapely.union_all(polygons(model.node_x.values, model.node_y.values, counts_all)[supports])
        areas = list(shapely.simplify(shapely.get_parts(merged), 0.0))  # no vertex left between collinear edges
    else:
        areas = [made_ground(node_x, node_y, counts, np.ones(counts.size, dtype=bool))]
    bounds = shapely.bounds(areas)
    x0, x1 = float(bounds[:, 0].min()), float(bounds[:, 2].max())
    xmin, xmax, _, _ = block_bounds(node_x, node_y, counts)
    edges = np.linspace(x0, x1, segment_count(x1 - x0, segment, float(np.median(xmax - xmin)), key) + 1)
    carried = shapely.union_all(polygons(node_x, node_y, counts)).boundary
    tol = 1e-6 * float(np.hypot(np.ptp(node_x), np.ptp(node_y)))
    pieces = ground_pieces(areas, carried, edges, tol)
    if not pieces:
        raise SpecError("no masonry rests on the wall's ground (its support blocks, or one made under its lowest "
                        "edges): nothing to settle")
    rings = [np.asarray(piece.exterior.coords)[:-1] for piece, _ in pieces]
    node_x = np.concatenate([node_x, *(r[:, 0] for r in rings)])
    node_y = np.concatenate([node_y, *(r[:, 1] for r in rings)])
    counts = np.concatenate([counts, [r.shape[0] for r in rings]]).astype(np.int32)
    roles = np.concatenate([role[masonry], np.full(len(rings), ROLE["fixed_support"])]).astype(np.int8)
    thickness = np.concatenate([model.block_thickness.values[masonry],
                                np.full(len(rings), float(np.median(model.block_thickness.values[masonry])))])
    held = [blocks.Support(f"ground segment {k} [{edges[k]:.6g}, {edges[k + 1]:.6g}] m") for _, k in pieces]
    built = blocks.model_from_blocks(node_x, node_y, counts, roles, thickness, masonry_material(model), held,
                                     "settlement", attrs={"title": model.attrs.get("title", "")})
    return derive_geometry(built)


def over_profile(model: xr.Dataset, profile: Profile) -> xr.Dataset:
    """``model`` (a wall on its ground segments, :func:`ground_model`) with every segment moving as ``profile``
    says (a continuous ground follows the profile at both ends of each segment, a step translates the
    segments under it), recording the profile; the geometry and the interfaces kept."""
    role = model.block_role.values
    ground = np.flatnonzero(support_blocks(role))
    xmin, xmax, _, ymax = block_bounds(model.node_x.values, model.node_y.values, model.block_node_count.values)
    supports = []
    for block in ground:
        a, b = float(xmin[block]), float(xmax[block])
        if profile.kind == "step":
            rate = float(profile.rate(np.array([0.5 * (a + b)]))[0])
            down, sideways = np.array([rate, rate]), np.zeros(2)
        else:
            down, sideways = node_motion(profile, np.array([a, b]))
        edge = blocks.GroundEdge((a, b), float(ymax[block]), tuple(map(float, down)), tuple(map(float, sideways)))
        supports.append(blocks.Support(f"ground block {block}", "moving", "ground", ground=edge) if down.max() > 0
                        else blocks.Support(f"ground block {block}"))
    if not any(s.kind == "moving" for s in supports):
        raise SpecError("the profile moves no segment of the ground under the wall")
    return with_profile(blocks.with_supports(model, supports), profile)
