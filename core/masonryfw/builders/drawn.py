"""Walls drawn elsewhere: a spec whose ``[geometry]`` table points at a drawing.

The drawing gives the blocks (:mod:`masonryfw.readers.drawing`); the spec gives what a
drawing cannot: the wall thickness, the material, which blocks are supports and
how they move, and the loading. The keys (``docs/import.md``)::

    [geometry]
    dxf = "wall.dxf"          # or polygons = "blocks.csv" / "blocks.geojson"; relative to the spec file
    drawing_unit = "mm"       # m, cm or mm; overrides the DXF's $INSUNITS
    chord_tolerance = 0.5     # optional, drawing units: arcs become chords this close to them
    snap_tolerance = 0.001    # optional, drawing units (default 1e-6 of the drawing's size)
    [geometry.layers]         # optional: the role of the blocks on a layer
    LINTELS = "lintel"        # unit (default), lintel, or ignore (left out)
    [supports.base]
    kind = "fixed"
    select = "lowest"         # lowest, leftmost or rightmost block; or layer = "BASE"; or at = [x, y]
    [supports.settling]
    kind = "moving"
    layer = "SETTLE"          # every block on this layer is this support
    motion = "translation"    # or "rotation" with pivot = [x, y]

Lengths written in the spec (``wall.thickness``, ``pivot``, ``at``) are in its
``length_unit`` (m unless said); the drawing's are in ``drawing_unit``. The
parametric keys (``[unit]``, ``[bond]``, ``[openings]``, ``wall.width``,
``wall.height``, support ``start``/``end``) do not apply and are refused.
Blocks come in drawing order (units and lintels), then the supports in spec
order; loads, interfaces and kinds as for every model (:mod:`masonryfw.builders.blocks`).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..format.model import checked_model
from ..format.roles import ROLE
from ..geometry.polygons import block_bounds, polygon_area_centroid
from ..ground.profiles import SETTLEMENT_KEYS, profile_segments, read_profile, with_profile
from ..readers.drawing import DRAWING_UNITS, Drawing, read_drawing
from ..readers.material import Material
from ..readers.spec import (
    MOTION_KEYS,
    SpecTable,
    check_pivot,
    model_attributes,
    open_spec,
    read_loading,
    read_material,
    read_motion,
    refuse_ground_twice,
    spec_relative,
)
from ..runtime.errors import ModelError, SpecError
from . import blocks
from .ground import ground_pieces, made_ground, polygons

if TYPE_CHECKING:  # annotations only
    import xarray as xr

LAYER_ROLES = ("unit", "lintel", "ignore")
_BLOCK = re.compile(r"\bblock (\d+)\b")
SELECTIONS = ("lowest", "leftmost", "rightmost")
_TOP_KEYS = ("title", "description", "space", "length_unit", "geometry", "wall", "material", "supports", "settlement",
             "loading")
#: The keys a drawn wall's ``[settlement]`` takes beside a profile's: which drawn blocks are the ground.
GROUND_KEYS = ("ground_layer", "ground_select")
_GEOMETRY_KEYS = ("dxf", "polygons", "drawing_unit", "chord_tolerance", "snap_tolerance", "layers")
_SUPPORT_KEYS = ("kind", "select", "layer", "at", *MOTION_KEYS)
_PARAMETRIC = {
    "unit": "the drawing gives the blocks; to lay a bond in an outline, name its layer: geometry.outline_layer",
    "bond": "the drawing gives the blocks; to lay a bond in an outline, name its layer: geometry.outline_layer",
    "heads": "the drawing gives the blocks; to lay a bond in an outline, name its layer: geometry.outline_layer",
    "openings": "openings are drawn (left empty) in the drawing",
}


@dataclass(frozen=True)
class DrawnSupport:
    """A support of a drawn wall: how its blocks are chosen and how they move (SI)."""

    name: str
    kind: str
    how: str  # select, layer or at
    what: object  # the selection keyword, the layer name or the point (m)
    motion: str
    pivot: tuple[float, float] | None
    rate: float
    direction: tuple[float, float]
    table: SpecTable


@dataclass(frozen=True)
class DrawnSpec:
    """A validated ``[geometry]`` spec, lengths in metres (the drawing not read yet)."""

    title: str
    description: str
    drawing: str  # path as written
    drawing_key: str  # dxf or polygons
    drawing_unit: str | None
    chord_tolerance: float | None
    snap_tolerance: float | None
    layers: dict[str, str]
    thickness: float
    material: Material
    supports: tuple[DrawnSupport, ...]
    loading: str
    tilt_direction: int
    settlement: SpecTable | None = None  # the [settlement] table, read once the drawing gives the wall's extent


def is_drawn(spec: dict) -> bool:
    """Whether a spec dict describes a drawn wall (it has a ``[geometry]`` table)."""
    return isinstance(spec, dict) and "geometry" in spec


def parse_drawn_spec(spec: dict) -> DrawnSpec:
    """Validate a ``[geometry]`` spec; a :class:`SpecError` names the key at fault."""
    for key, why in _PARAMETRIC.items():
        if key in spec:
            raise SpecError(f"spec key {key!r} does not apply to a wall drawn in [geometry] ({why})")
    top = open_spec(spec, _TOP_KEYS)
    geometry = top.sub("geometry", _GEOMETRY_KEYS)
    sources = [k for k in ("dxf", "polygons") if geometry.has(k)]
    if len(sources) != 1:
        raise SpecError("spec table 'geometry': give exactly one of 'geometry.dxf' (a DXF drawing) and "
                        "'geometry.polygons' (a CSV or GeoJSON file of block outlines)"
                        + (", not both" if sources else ""))
    drawing_unit = geometry.raw("drawing_unit", None)
    if drawing_unit is not None and drawing_unit not in DRAWING_UNITS:
        geometry.choice("drawing_unit", tuple(DRAWING_UNITS))
    layers_table = geometry.raw("layers", {})
    if not isinstance(layers_table, dict):
        raise SpecError(f"spec key 'geometry.layers' = {layers_table!r}: must be a table of layer = role")
    layers = {}
    for layer, role in layers_table.items():
        if role not in LAYER_ROLES:
            raise SpecError(f"spec key 'geometry.layers.{layer}' = {role!r}: must be one of "
                            f"{', '.join(map(repr, LAYER_ROLES))}")
        layers[str(layer)] = role
    wall = top.raw("wall", {})
    for key in ("width", "height"):
        if isinstance(wall, dict) and key in wall:
            raise SpecError(f"spec key 'wall.{key}' does not apply to a wall drawn in [geometry] "
                            "(the drawing gives its size)")
    wall = top.sub("wall", ("thickness",))
    material = read_material(top)
    refuse_ground_twice(top, "the profile makes the supports; drawn ground blocks are chosen by "
                             "settlement.ground_layer or settlement.ground_select")
    settlement = top.sub("settlement", SETTLEMENT_KEYS + GROUND_KEYS) if top.has("settlement") else None
    supports = () if settlement is not None else _drawn_supports(top, layers)
    loading, direction = read_loading(top, settlement is not None or any(s.kind == "moving" for s in supports))
    return DrawnSpec(
        title=top.text("title"),
        description=top.text("description", ""),
        drawing=geometry.text(sources[0]),
        drawing_key=f"geometry.{sources[0]}",
        drawing_unit=drawing_unit,
        chord_tolerance=geometry.number("chord_tolerance", None, positive=True),
        snap_tolerance=geometry.number("snap_tolerance", None, positive=True),
        layers=layers,
        thickness=wall.number("thickness", length=True, positive=True),
        material=material,
        supports=supports,
        loading=loading,
        tilt_direction=direction,
        settlement=settlement,
    )


def _drawn_supports(top: SpecTable, layers: dict[str, str]) -> tuple[DrawnSupport, ...]:
    table = top.raw("supports")
    if not isinstance(table, dict) or not table:
        raise SpecError(f"spec key 'supports' = {table!r}: must hold at least one [supports.<name>] table")
    supports = []
    for name in table:
        entry = table[name]
        for key in ("start", "end"):
            if isinstance(entry, dict) and key in entry:
                raise SpecError(f"spec key 'supports.{name}.{key}' does not apply to a wall drawn in [geometry]: "
                                "choose the support's blocks by select, layer or at")
        entry = SpecTable(entry, f"supports.{name}", _SUPPORT_KEYS, top.scale)
        kind = entry.choice("kind", ("fixed", "moving"))
        ways = [k for k in ("select", "layer", "at") if entry.has(k)]
        if len(ways) != 1:
            raise SpecError(f"spec table 'supports.{name}': choose its blocks with exactly one of select "
                            f"({', '.join(SELECTIONS)}), layer or at" + (f" (found {', '.join(ways)})" if ways else ""))
        how = ways[0]
        if how == "select":
            what: object = entry.choice("select", SELECTIONS)
        elif how == "layer":
            what = entry.text("layer")
            if what in layers:
                raise SpecError(f"spec keys 'supports.{name}.layer' and 'geometry.layers.{what}': the layer "
                                f"{what!r} cannot be both a support and {layers[what]!r}")
        else:
            what = entry.point("at")
        motion, pivot, rate, direction = read_motion(entry, kind)
        supports.append(DrawnSupport(name, kind, how, what, motion, pivot, rate, direction, entry))
    return tuple(supports)


def resolved_drawing(spec: DrawnSpec, base_dir: Path | None) -> Path:
    """The drawing's path: as written if absolute, else relative to ``base_dir`` (the spec file's folder)."""
    return spec_relative(spec.drawing, base_dir)


def build_drawn(spec_dict: dict, text: str, base_dir: Path | None, validate: bool = True) -> xr.Dataset:
    """The model of a drawn wall (see the module docstring); checked unless ``validate`` is False."""
    spec = parse_drawn_spec(spec_dict)
    path = resolved_drawing(spec, base_dir)
    if not path.exists():
        raise SpecError(f"spec key {spec.drawing_key!r} = {spec.drawing!r}: no such file ({path})")
    drawing = read_drawing(path, spec.drawing_unit, spec.chord_tolerance, spec.snap_tolerance)
    kept = np.array([spec.layers.get(layer, "unit") != "ignore" for layer in drawing.layers])
    _refuse_an_elevation(drawing, kept, path)
    attrs = model_attributes(spec.title, spec.description, text, drawing=path)
    if spec.settlement is None:
        ds, labels = _drawn_supports_model(spec, drawing, kept, path, attrs)
    else:
        ds, labels = _ground_model(spec, drawing, kept, path, attrs)
    if not validate:
        return ds
    try:
        return checked_model(ds, repr(spec.title))
    except ModelError as exc:
        raise ModelError(f"model {spec.title!r} from drawing {path.name!r} is invalid "
                         f"({len(exc.problems)} problem(s))",
                         [_labelled(p, labels) for p in exc.problems]) from None


def _refuse_an_elevation(drawing: Drawing, kept: np.ndarray, path: Path) -> None:
    """A drawing of an outline and its openings (blocks inside a block), or of one block the size of the wall,
    is not a drawing of blocks: refused, saying how to lay a bond in it (an architect's elevation took every
    closed polyline for a brick, or built one block 6.5 m x 10.5 m)."""
    import shapely

    shapes = polygons(drawing.node_x, drawing.node_y, drawing.block_node_count)
    chosen = np.flatnonzero(kept)
    inner, outer = shapely.STRtree(shapes[chosen]).query(shapely.point_on_surface(shapes[chosen]), "within")
    nested = inner != outer
    howto = ("lay a bond in it: [geometry] outline_layer = {outline!r}{openings}, with [unit] (length, course "
             "height) and, if you like, [bond] and [heads] (docs/import.md)")
    if nested.any():
        container = chosen[np.bincount(outer[nested], minlength=chosen.size).argmax()]
        held = chosen[inner[nested][outer[nested] == np.flatnonzero(chosen == container)[0]]]
        layers = sorted({drawing.layers[b] for b in held})
        x0, y0, x1, y1 = shapes[container].bounds
        raise SpecError(f"drawing {path.name!r}: {drawing.label(container)} ({x1 - x0:.4g} x {y1 - y0:.4g} m) holds "
                        f"{held.size} other closed polyline(s) (on layer {', '.join(layers)}): an elevation's outline "
                        "and its openings, not one polyline per block; " + howto.format(
                            outline=drawing.layers[container], openings=f", openings_layer = {layers[0]!r}"))
    if chosen.size == 1:
        x0, y0, x1, y1 = shapes[chosen[0]].bounds
        raise SpecError(f"drawing {path.name!r}: its masonry would be one block, {drawing.label(chosen[0])} "
                        f"({x1 - x0:.4g} x {y1 - y0:.4g} m); a wall of one block is no masonry: if it is the wall's "
                        "outline, " + howto.format(outline=drawing.layers[chosen[0]], openings=""))


def _masonry_roles(spec: DrawnSpec, drawing: Drawing, masonry: np.ndarray) -> list[int]:
    return [ROLE["lintel"] if spec.layers.get(drawing.layers[b]) == "lintel" else ROLE["unit"]
            for b in masonry]


def _drawn_supports_model(spec: DrawnSpec, drawing: Drawing, kept: np.ndarray, path: Path,
                          attrs: dict) -> tuple[xr.Dataset, list[str]]:
    """The model of a wall on its drawn supports (``[supports.*]``) and the drawing entity of every block."""
    chosen = _chosen_supports(spec, drawing, kept)
    supports_of = np.full(len(drawing.layers), -1)
    for index, members in enumerate(chosen):
        supports_of[members] = index
    masonry = np.flatnonzero(kept & (supports_of < 0))
    if masonry.size == 0:
        raise SpecError(f"drawing {path.name!r}: every block is a support or ignored; nothing to analyse")
    support_order = np.concatenate([members for members in chosen])
    order = np.concatenate((masonry, support_order))
    roles = np.array(_masonry_roles(spec, drawing, masonry) + [ROLE["fixed_support"]] * support_order.size,
                     dtype=np.int8)
    described = [blocks.Support(f"spec key 'supports.{s.name}'", s.kind, s.motion, s.pivot, s.rate,
                                direction=s.direction)
                 for s, members in zip(spec.supports, chosen) for _ in members]
    node_x, node_y, counts = _reordered(drawing, order)
    _check_pivots(spec, chosen, drawing)
    labels = [drawing.label(b) for b in order]
    ds = blocks.model_from_blocks(node_x, node_y, counts, roles, spec.thickness, spec.material, described,
                                  spec.loading, spec.tilt_direction, attrs)
    _refuse_lonely_supports(ds, spec, chosen, masonry.size, labels)
    return ds, labels


def _ground_model(spec: DrawnSpec, drawing: Drawing, kept: np.ndarray, path: Path,
                  attrs: dict) -> tuple[xr.Dataset, list[str]]:
    """The model of a drawn wall over a ``[settlement]`` profile: its ground (the drawn blocks chosen by
    ``ground_layer`` or ``ground_select``, else a ground one median block high under the masonry's lowest
    edges) cut into the segments of a continuous ground (:mod:`masonryfw.ground.profiles`), the pieces that carry
    masonry kept (:func:`masonryfw.builders.ground.ground_pieces`)."""
    import shapely

    ground = _ground_blocks(spec.settlement, drawing, kept)
    masonry = np.flatnonzero(kept & ~np.isin(np.arange(kept.size), ground))
    if masonry.size == 0:
        raise SpecError(f"drawing {path.name!r}: every block is ground or ignored; nothing to analyse")
    if ground.size:
        _refuse_a_ground_above(spec.settlement, drawing, ground, masonry)
    drawn = polygons(drawing.node_x, drawing.node_y, drawing.block_node_count)
    xmin, xmax, _, _ = block_bounds(drawing.node_x, drawing.node_y, drawing.block_node_count)
    is_masonry = np.isin(np.arange(kept.size), masonry)
    areas = list(drawn[ground]) if ground.size else [
        made_ground(drawing.node_x, drawing.node_y, drawing.block_node_count, is_masonry)]
    x0, x1 = (float(f(shapely.bounds(areas)[:, k])) for f, k in ((np.min, 0), (np.max, 2)))
    profile = read_profile(spec.settlement, x0, x1, float(np.median(xmax[masonry] - xmin[masonry])))
    segments = profile_segments(profile, x0, x1, np.array([[x0, x1]]))
    tol = 1e-6 * float(np.hypot(np.ptp(drawing.node_x), np.ptp(drawing.node_y)))
    pieces = ground_pieces(areas, shapely.union_all(drawn[masonry]).boundary,
                           np.array([s.start for s in segments] + [segments[-1].end]), tol)
    _refuse_a_still_ground(spec.settlement, [(shapely.bounds(piece), segments[k].moving) for piece, k in pieces])
    described, labels = [], []
    for piece, k in pieces:
        segment = segments[k]
        name = f"settlement segment {k} [{segment.start:.6g}, {segment.end:.6g}] m"
        edge = blocks.GroundEdge((segment.start, segment.end), float(shapely.bounds(piece)[3]), segment.down,
                                 segment.horizontal)
        described.append(blocks.Support(name, "moving", "ground", ground=edge) if segment.moving
                         else blocks.Support(name, "fixed"))
        labels.append(name)
    node_x, node_y, counts = _reordered(drawing, masonry)
    rings = [np.asarray(piece.exterior.coords)[:-1] for piece, _ in pieces]
    node_x = np.concatenate([node_x, *(r[:, 0] for r in rings)])
    node_y = np.concatenate([node_y, *(r[:, 1] for r in rings)])
    counts = np.concatenate([counts, [r.shape[0] for r in rings]]).astype(np.int32)
    roles = np.array(_masonry_roles(spec, drawing, masonry) + [ROLE["fixed_support"]] * len(rings),
                     dtype=np.int8)
    ds = blocks.model_from_blocks(node_x, node_y, counts, roles, spec.thickness, spec.material, described,
                                  spec.loading, spec.tilt_direction, attrs)
    return with_profile(ds, profile), [drawing.label(b) for b in masonry] + labels


def _refuse_a_still_ground(table: SpecTable, pieces: list[tuple[np.ndarray, bool]]) -> None:
    """A profile that moves none of the ground pieces carrying masonry (a step over a gap of the drawn ground)
    would settle nothing: refused, naming the keys and where the masonry rests."""
    if any(moving for _, moving in pieces):
        return
    resting = ", ".join(f"{b[0]:.4g}..{b[2]:.4g}" for b, _ in pieces)
    raise SpecError(f"spec table {table.path!r}: the profile moves none of the ground "
                    f"that carries masonry (it rests on the ground over x = {resting} m): nothing would settle; "
                    "move its keys (start, end, center) over those, or fill the gap in the drawn ground")


def _refuse_a_ground_above(table: SpecTable, drawing: Drawing, ground: np.ndarray, masonry: np.ndarray) -> None:
    """The ground chosen by ``ground_layer``/``ground_select`` must lie under the masonry (a layer of bricks given as
    the ground built a wall upside down that ``check`` passed)."""
    _, _, ymin, ymax = block_bounds(drawing.node_x, drawing.node_y, drawing.block_node_count)
    low, high = ymin[masonry].min(), ymax[masonry].max()
    if ymax[ground].max() > low + 0.5 * (high - low):
        key = table.key("ground_layer" if table.has("ground_layer") else "ground_select")
        raise SpecError(f"spec key {key!r}: its blocks reach y = {ymax[ground].max():.4g} m, above the middle of the "
                        f"masonry (y {low:.4g}..{high:.4g} m); the ground lies under the wall: is it the masonry's "
                        "layer?")


def _ground_blocks(table: SpecTable, drawing: Drawing, kept: np.ndarray) -> np.ndarray:
    """The drawing's blocks that are the ground under a ``[settlement]`` (``ground_layer`` or
    ``ground_select``); empty when the ground is made under the masonry."""
    if table.has("ground_layer") and table.has("ground_select"):
        raise SpecError(f"spec keys {table.key('ground_layer')!r} and {table.key('ground_select')!r}: give one of them")
    if table.has("ground_layer"):
        layer = table.text("ground_layer")
        members = np.flatnonzero(kept & (np.array(drawing.layers) == layer))
        if members.size == 0:
            raise SpecError(f"spec key {table.key('ground_layer')!r} = {layer!r}: no block of the drawing (left) on "
                            f"this layer; the drawing's layers: {', '.join(sorted(set(drawing.layers)))}")
        return members
    if not table.has("ground_select"):
        return np.zeros(0, dtype=np.int64)
    table.choice("ground_select", ("lowest",))
    _, _, ymin, _ = block_bounds(drawing.node_x, drawing.node_y, drawing.block_node_count)
    value = np.where(kept, ymin, np.inf)
    tol = 1e-6 * float(np.hypot(np.ptp(drawing.node_x), np.ptp(drawing.node_y)))
    best = np.flatnonzero(value <= value.min() + tol)
    if best.size > 1:
        raise SpecError(f"spec key {table.key('ground_select')!r} = 'lowest': {best.size} blocks tie "
                        f"({'; '.join(drawing.label(b) for b in best[:3])}); choose them by ground_layer")
    return best


def _chosen_supports(spec: DrawnSpec, drawing: Drawing, kept: np.ndarray) -> list[np.ndarray]:
    """The drawing's blocks of every support, in spec order; a selection matching nothing or twice is refused."""
    xmin, xmax, ymin, _ = block_bounds(drawing.node_x, drawing.node_y, drawing.block_node_count)
    taken = np.full(kept.size, -1)
    chosen = []
    tol = 1e-6 * float(np.hypot(np.ptp(drawing.node_x), np.ptp(drawing.node_y)))
    for index, support in enumerate(spec.supports):
        key = f"supports.{support.name}.{support.how}"
        candidates = kept & (taken < 0)
        if support.how == "layer":
            members = np.flatnonzero(candidates & (np.array(drawing.layers) == support.what))
            if members.size == 0:
                layers = sorted(set(drawing.layers))
                raise SpecError(f"spec key {key!r} = {support.what!r}: no block of the drawing (left) on this "
                                f"layer; the drawing's layers: {', '.join(layers)}")
        elif support.how == "at":
            members = _blocks_containing(drawing, support.what, candidates)
            if members.size == 0:
                raise SpecError(f"spec key {key!r} = {list(support.what)!r}: the point lies in no block of the "
                                "drawing (lengths in the spec's length_unit)")
        else:
            value = {"lowest": ymin, "leftmost": xmin, "rightmost": -xmax}[support.what]
            value = np.where(candidates, value, np.inf)
            best = np.flatnonzero(value <= value.min() + tol)
            if best.size > 1:
                names = "; ".join(drawing.label(b) for b in best[:3])
                raise SpecError(f"spec key {key!r} = {support.what!r}: {best.size} blocks tie ({names}); "
                                "choose by layer or at")
            members = best
        clash = members[taken[members] >= 0]
        if clash.size:
            raise SpecError(f"spec key {key!r}: {drawing.label(clash[0])} is already support "
                            f"{spec.supports[taken[clash[0]]].name!r}")
        taken[members] = index
        chosen.append(members)
    return chosen


def _blocks_containing(drawing: Drawing, point, candidates: np.ndarray) -> np.ndarray:
    import shapely

    drawn = polygons(drawing.node_x, drawing.node_y, drawing.block_node_count)
    inside = shapely.contains_xy(drawn, point[0], point[1]) | shapely.touches(drawn, shapely.points(point))
    return np.flatnonzero(inside & candidates)


def _reordered(drawing: Drawing, order: np.ndarray):
    """The drawing's polygons in block order ``order``."""
    counts = drawing.block_node_count[order]
    first = np.repeat(np.concatenate(([0], np.cumsum(drawing.block_node_count)))[order], counts)
    nodes = first + np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    return drawing.node_x[nodes], drawing.node_y[nodes], counts


def _check_pivots(spec: DrawnSpec, chosen: list[np.ndarray], drawing: Drawing) -> None:
    cx = polygon_area_centroid(drawing.node_x, drawing.node_y, drawing.block_node_count)[1]
    tol = 1e-9 * float(np.hypot(np.ptp(drawing.node_x), np.ptp(drawing.node_y)))
    for support, members in zip(spec.supports, chosen):
        for block in members:
            check_pivot(support.table, support.pivot, float(cx[block]), tol)


def _refuse_lonely_supports(ds: xr.Dataset, spec: DrawnSpec, chosen, n_masonry: int, labels: list[str]) -> None:
    """Every support block must touch the masonry: one that does not is named with its entity."""
    sides = ds.interface_blocks.values
    touched = np.zeros(ds.sizes["block"], dtype=bool)
    touched[sides.ravel()] = True
    first = n_masonry
    for support, members in zip(spec.supports, chosen):
        for offset in range(members.size):
            block = first + offset
            if not touched[block]:
                raise SpecError(f"spec table 'supports.{support.name}': {labels[block]} touches no masonry "
                                "(no common edge with a unit or lintel)")
        first += members.size


def _labelled(problem, labels: list[str]):
    """``problem`` with every ``block N`` it names followed by the drawing entity the block came from."""
    def named(match: re.Match) -> str:
        block = int(match.group(1))
        return f"{match.group(0)} ({labels[block]})" if block < len(labels) else match.group(0)

    return replace(problem, where=_BLOCK.sub(named, problem.where), message=_BLOCK.sub(named, problem.message))
