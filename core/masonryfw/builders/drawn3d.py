"""Walls and buildings drawn in 3D: a spec whose ``[geometry]`` points at an OBJ ``mesh`` of closed polyhedra,
one per block (:mod:`masonryfw.readers.drawing3d`), standing on ground made under them that follows a settlement
profile in plan (docs/import.md, "3D drawings")::

    space = 3
    [geometry]
    mesh = "house.obj"        # relative to the spec file
    drawing_unit = "mm"       # m (default), cm or mm
    snap_tolerance = 0.01     # optional, drawing units (default 1e-6 of the drawing's size)
    ground_depth = 200.0      # optional, the spec's length unit (default the blocks' median height)
    [geometry.layers]         # optional: the role of the blocks on a layer (their material or group)
    LINTELS = "lintel"        # unit (default), lintel, or ignore (left out)
    [material]
    ...
    [settlement]              # as a building's: a 2D profile across an axis in plan, a tunnel's face

The ground is made under the masonry's lowest faces (those facing down at its lowest level): their outline in
plan cut by a grid of square cells ``settlement.segment`` wide (default a quarter of the blocks' median length;
the cells fit the outline's extent in whole numbers), each piece a ground block ``ground_depth`` deep whose top
follows the ground at its vertices (:func:`masonryfw.builders.on_ground.plane_motion`).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import shapely
import xarray as xr
from shapely.geometry.polygon import orient

from ..format.roles import ROLE
from ..geometry import polyhedra
from ..geometry.polygons import block_offsets
from ..ground.ground_plan import SETTLEMENT_3D_KEYS, GroundInPlan, profile_in_plan
from ..ground.profiles import with_profile
from ..readers.drawing import DRAWING_UNITS
from ..readers.drawing3d import MeshDrawing, read_obj
from ..readers.spec import SpecTable, model_attributes, open_spec, read_material, spec_relative
from ..runtime.errors import SpecError
from ..runtime.inputs import InputError, regular_file
from .drawn import LAYER_ROLES
from .on_ground import model_on_ground, plane_motion

GEOMETRY_KEYS = ("mesh", "drawing_unit", "snap_tolerance", "ground_depth", "layers")
TOP_KEYS = ("title", "description", "space", "length_unit", "geometry", "material", "settlement")
#: A layer's role (the 2D drawings' names) as the block role it gives; -1 leaves its blocks out.
LAYER_ROLE_CODES = {name: ROLE.get(name, -1) for name in LAYER_ROLES}


def is_drawn_3d(spec: dict) -> bool:
    """Whether a spec dict describes a 3D drawing (its ``[geometry]`` has a ``mesh``)."""
    return isinstance(spec, dict) and isinstance(spec.get("geometry"), dict) and "mesh" in spec["geometry"]


def mesh_path(spec: dict, base_dir: Path | None) -> Path:
    """The mesh's path: as written if absolute, else relative to ``base_dir`` (the spec file's folder); a
    :class:`SpecError` when ``geometry.mesh`` is not a path."""
    written = spec["geometry"]["mesh"]
    if not isinstance(written, str):
        raise SpecError(f"spec key 'geometry.mesh' = {written!r}: must be the path of an OBJ file")
    return spec_relative(written, base_dir)


def build_drawn_3d(spec: dict, text: str, base_dir: Path | None) -> xr.Dataset:
    """The 3D model of a spec whose ``[geometry]`` has a ``mesh`` (module docstring); a :class:`SpecError` names
    the key, the block or the line at fault."""
    top = open_spec(spec, TOP_KEYS, three_d="a mesh")
    geometry = top.sub("geometry", GEOMETRY_KEYS)
    unit = DRAWING_UNITS[geometry.choice("drawing_unit", tuple(DRAWING_UNITS), "m")]
    path = mesh_path(spec, base_dir)
    try:
        regular_file(path, "3D drawing (an OBJ mesh)", f"spec key 'geometry.mesh' = {geometry.raw('mesh')!r}")
    except InputError as exc:
        raise SpecError(str(exc)) from None
    if path.suffix.lower() != ".obj":
        raise SpecError(f"spec key 'geometry.mesh' = {geometry.raw('mesh')!r}: a Wavefront OBJ file (.obj) is read")
    snap = geometry.number("snap_tolerance", None, positive=True)
    drawing = read_obj(path, snap)
    roles = _layer_roles(geometry, drawing)
    masonry = _scaled(polyhedra.subset(drawing.blocks, roles >= 0), unit)
    names = [name for name, role in zip(drawing.names, roles) if role >= 0]
    lines = [line for line, role in zip(drawing.lines, roles) if role >= 0]
    label = lambda b: f"block {names[b]!r} (line {lines[b]})"  # noqa: E731 - how messages name a drawn block
    _refuse_overlaps(masonry, path.name, label)
    material = read_material(top)
    if not top.has("settlement"):
        raise SpecError("spec table 'settlement' is missing: a drawn 3D model stands on ground that moves by a "
                        "profile in plan ([settlement] with profile, axis_angle, center_x, center_y)")
    length, height = _typical_unit(masonry)
    ground_plan = profile_in_plan(top.sub("settlement", SETTLEMENT_3D_KEYS), length,
                                  float(np.ptp(masonry.vertices[:, :2], axis=0).max()))
    depth = geometry.number("ground_depth", height / top.scale, length=True, positive=True)
    tol = 1e-6 * float(np.ptp(masonry.vertices, axis=0).max())
    pieces, level = _ground_pieces(masonry, ground_plan.profile.segment, tol, path.name)
    ground = polyhedra.vertical_prisms(*_rings(pieces), np.full(len(pieces), level - depth), np.full(len(pieces), level))
    motion = np.array([_piece_motion(ground_plan, piece, depth) for piece in pieces])
    volume, _ = polyhedra.volumes_centroids(masonry)
    attrs = model_attributes(top.text("title"), top.text("description", ""), text, drawing=path, notes=drawing.notes, settlement_axis=ground_plan.axis_attr())
    model = model_on_ground(polyhedra.joined(masonry, ground), roles[roles >= 0], material.unit_weight * volume,
                            motion, material, attrs, tol, "piece of the ground",
                            lambda b: f"drawing {path.name!r}: {label(b)}")
    return with_profile(model, ground_plan.profile)


def _refuse_overlaps(masonry: polyhedra.Polyhedra, name: str, label) -> None:
    """Refuse blocks that interpenetrate (:func:`masonryfw.geometry.polyhedra.overlapping_blocks`), naming the first pair and
    what it looks like: the same block twice, one inside the other, or two laid into one another."""
    size = float(np.ptp(masonry.vertices, axis=0).max())
    found = polyhedra.overlapping_blocks(masonry, 1e-6 * size, most=1)
    if not found:
        return
    a, b, depth, shared, point = found[0]
    volume, _ = polyhedra.volumes_centroids(masonry)
    if np.isfinite(shared) and shared >= (1 - 1e-6) * max(volume[a], volume[b]):
        what = "the same block drawn twice"
    elif np.isfinite(shared) and shared >= (1 - 1e-6) * min(volume[a], volume[b]):
        what = "one inside the other"
    else:
        what = "laid into one another"
    common = f"{shared:.3g} m3 in common" if np.isfinite(shared) else "a point of one inside the other"
    raise SpecError(f"drawing {name!r}: {label(a)} and {label(b)} interpenetrate ({what}: {common}, at "
                    f"({', '.join(f'{c:.6g}' for c in point)}) m); blocks may touch, never overlap")


def _layer_roles(geometry: SpecTable, drawing: MeshDrawing) -> np.ndarray:
    """Every drawn block's role by its layer (``geometry.layers``; unit by default, -1 to leave it out)."""
    table = geometry.raw("layers", {})
    if not isinstance(table, dict):
        raise SpecError(f"spec key 'geometry.layers' = {table!r}: must be a table of layer = role")
    for layer, role in table.items():
        if role not in LAYER_ROLE_CODES:
            raise SpecError(f"spec key 'geometry.layers.{layer}' = {role!r}: must be one of "
                            f"{', '.join(map(repr, LAYER_ROLE_CODES))}")
        if layer not in drawing.layers:
            raise SpecError(f"spec key 'geometry.layers.{layer}': no block of the drawing is on that layer (its "
                            f"layers: {', '.join(sorted(set(drawing.layers)))})")
    roles = np.array([LAYER_ROLE_CODES[table.get(layer, "unit")] for layer in drawing.layers])
    if not (roles >= 0).any():
        raise SpecError("spec key 'geometry.layers': every block of the drawing is left out")
    return roles


def _scaled(blocks: polyhedra.Polyhedra, unit: float) -> polyhedra.Polyhedra:
    return blocks._replace(vertices=blocks.vertices * unit)


def _typical_unit(blocks: polyhedra.Polyhedra) -> tuple[float, float]:
    """The blocks' median length (their longer side in plan) and height [m]: what a unit is in a drawing."""
    owner = np.repeat(np.arange(blocks.n_block), blocks.block_node_count)
    low = np.full((blocks.n_block, 3), np.inf)
    high = np.full((blocks.n_block, 3), -np.inf)
    np.minimum.at(low, owner, blocks.vertices)
    np.maximum.at(high, owner, blocks.vertices)
    size = high - low
    return float(np.median(size[:, :2].max(axis=1))), float(np.median(size[:, 2]))


def _ground_pieces(blocks: polyhedra.Polyhedra, segment: float, tol: float, name: str
                   ) -> tuple[np.ndarray, float]:
    """The outline in plan of the faces at the masonry's lowest level facing down, cut by a grid of cells about
    ``segment`` wide (whole cells over its extent): simple polygons (a piece with a hole is cut through it), and
    that level."""
    level = float(blocks.vertices[:, 2].min())
    index = blocks.face_vertex_index()
    face_first = block_offsets(blocks.face_node_count)[:-1]
    normals, _ = polyhedra.polygon_normals(blocks.vertices[index], blocks.face_node_count)
    low = np.maximum.reduceat(blocks.vertices[index, 2], face_first) <= level + tol
    bottom = np.flatnonzero(low & (normals[:, 2] < -1 + 1e-6))
    outline = shapely.union_all([shapely.Polygon(blocks.vertices[index[face_first[f]:face_first[f] + n], :2])
                                 for f, n in zip(bottom, blocks.face_node_count[bottom])], grid_size=tol)
    x0, y0, x1, y1 = outline.bounds
    xs = np.linspace(x0, x1, max(1, round((x1 - x0) / segment)) + 1)
    ys = np.linspace(y0, y1, max(1, round((y1 - y0) / segment)) + 1)
    cells = shapely.box(*np.meshgrid(xs[:-1], ys[:-1]), *np.meshgrid(xs[1:], ys[1:]))
    pieces = [part for piece in shapely.intersection(outline, cells.ravel(), grid_size=tol)
              for part in _simple_parts(piece, tol)]
    if not pieces:
        raise SpecError(f"drawing {name!r}: no block has a face facing down at the masonry's lowest level "
                        f"(z = {level:.6g} m): nothing to stand on the ground")
    return np.array(pieces, dtype=object), level


def _simple_parts(geometry, tol: float) -> list:
    """The polygons of ``geometry`` with an area, any with a hole cut in two through the hole's centroid."""
    parts = []
    for part in shapely.get_parts(geometry):
        if not isinstance(part, shapely.Polygon) or part.area <= tol**2:
            continue
        if part.interiors:
            x = shapely.Polygon(part.interiors[0]).centroid.x
            x0, y0, x1, y1 = part.bounds
            halves = shapely.intersection(part, [shapely.box(x0, y0, x, y1), shapely.box(x, y0, x1, y1)], grid_size=tol)
            parts += [p for half in halves for p in _simple_parts(half, tol)]
        else:
            parts.append(orient(part, sign=1.0))
    return parts


def _rings(pieces: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The pieces' outlines as ragged arrays (x, y, count), counter-clockwise, no repeated last point."""
    rings = [np.asarray(piece.exterior.coords)[:-1] for piece in pieces]
    points = np.concatenate(rings)
    return points[:, 0], points[:, 1], np.array([len(r) for r in rings])


def _piece_motion(ground_plan: GroundInPlan, piece, depth: float) -> np.ndarray:
    points = np.asarray(piece.exterior.coords)[:-1]
    down, horizontal = ground_plan.motion(points)
    return plane_motion(down, horizontal, points, np.array(piece.centroid.coords[0]), depth)
