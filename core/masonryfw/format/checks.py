"""Validation of model, result and comparison datasets: every problem found, not only the first.

:func:`check` works in three layers, each only where the one before allows:

1. **format** (read from the schema, never duplicated here): global attributes
   and their fixed values, the format version, required variables, their dims,
   fixed dim sizes, dtype class, finite values, bounds and flag values;
2. **geometry**: every polygon (vertex count, repeated and collinear vertices,
   orientation, area, self-intersection; simple non-convex polygons are fine),
   overlapping blocks, and
   every interface (block indices, length, lying on an edge of both blocks);
3. **mechanics**: blocks and supports connected to nothing, settlement
   directions of moving and other blocks, the live load.

Each :class:`Problem` names where (``block 12``, ``interface 3``, ``variable
node_x``, ``attribute title``, ``dimension side``) and what, with coordinates
where they help (a vertex, a block centroid, an interface midpoint). Lengths are
compared with ``tol = 1e-6 * model_scale`` (bounding-box diagonal).
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..geometry.overlaps import overlapping_blocks, self_intersections
from ..geometry.polygons import (
    block_bounds,
    block_offsets,
    carrying_edges,
    model_scale,
    next_node,
    node_block,
    point_segment_distance,
    polygon_area_centroid,
    vertex_turns,
)
from ..geometry.polyhedra import polygon_normals, volumes_centroids
from .dofs import upgrade
from .model3d import interface_points, polyhedra_of, space
from .roles import moving_blocks, support_blocks
from .schema import FORMAT_VERSION, KINDS, KINDS_3D, READABLE_VERSIONS, load_schema

if TYPE_CHECKING:  # annotations only
    import xarray as xr

RELATIVE_TOLERANCE = 1e-6  # lengths below this fraction of the model scale count as zero


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a dataset: where it is, what it is, and (optionally) the point."""

    where: str
    message: str
    x: float | None = None
    y: float | None = None

    def __str__(self) -> str:
        at = "" if self.x is None or self.y is None else f" at ({self.x:.6g}, {self.y:.6g})"
        return f"{self.where}: {self.message}{at}"


def check(ds: xr.Dataset, kind: str | None = None, *, model_checked: bool = False) -> list[Problem]:
    """Every problem of a ``model``, ``result`` or ``comparison`` dataset (``[]`` when valid).

    ``kind`` defaults to the dataset's ``masonryfw_format`` attribute. A result
    may be checked as a model (a result holds its model): its format attribute
    may name any kind whose schema extends ``kind``. A dataset of an older
    format version is checked as it reads (upgraded, :func:`masonryfw.format.dofs.upgrade`).
    ``model_checked=True`` checks only what a result adds to a model already
    checked (its variables' format and its attributes), as :func:`masonryfw.solve`
    does with what a solver returned.
    """
    problems: list[Problem] = []
    kind = _dataset_kind(ds, kind, problems)
    if kind is None or not _version_is_known(ds, problems):
        return problems
    ds = upgrade(ds)
    in_3d = kind in KINDS_3D and space(ds) == 3
    schema = load_schema(KINDS_3D[kind] if in_3d else kind)
    if model_checked:
        return _added_variable_problems(ds, schema, kind, "model3d" if in_3d else "model")
    problems += _attribute_problems(ds, schema, kind)
    problems += _dimension_problems(ds, schema)
    usable, structure = _variable_structure_problems(ds, schema)
    problems += structure
    if in_3d:
        return (problems + _value_problems(ds, schema, usable, None) + _polyhedron_problems(ds, usable)
                + _support_problems(ds, usable, None) + _load_problems(ds, usable))
    model = _ModelGeometry.from_dataset(ds, usable, problems)
    problems += _value_problems(ds, schema, usable, model)
    if model is not None:
        problems += _polygon_problems(model)
        problems += _overlap_problems(model)
        problems += _interface_problems(model)
        problems += _connection_problems(ds, usable, model)
    problems += _support_problems(ds, usable, model)
    problems += _load_problems(ds, usable)
    return problems


def _added_variable_problems(ds, schema, kind, model_kind: str) -> list[Problem]:
    """The format layer for the variables a result adds to its (checked) model."""
    model_variables = load_schema(model_kind)["variables"]
    added = {**schema, "variables": {n: v for n, v in schema["variables"].items() if n not in model_variables}}
    problems = _attribute_problems(ds, added, kind)
    usable, structure = _variable_structure_problems(ds, added)
    return problems + structure + _value_problems(ds, added, usable, None)


# ---------------------------------------------------------------- format layer

def _dataset_kind(ds, kind, problems) -> str | None:
    stored = ds.attrs.get("masonryfw_format")
    if kind is None:
        if stored is None:
            problems.append(Problem(
                "attribute masonryfw_format",
                f"missing: cannot tell whether this is a {', '.join(KINDS[:-1])} or {KINDS[-1]} dataset",
            ))
            return None
        kind = str(stored)
    if kind not in KINDS:
        problems.append(Problem(
            "attribute masonryfw_format", f"unknown dataset kind {kind!r}; expected one of {', '.join(KINDS)}"
        ))
        return None
    return kind


def _version_is_known(ds, problems) -> bool:
    """False (with one clear problem) when the file claims a format version this code cannot read."""
    version = ds.attrs.get("masonryfw_format_version")
    if version is None:
        return True  # reported with the other required attributes
    try:
        number = int(np.asarray(version).item())
        known = number in READABLE_VERSIONS and float(np.asarray(version).item()) == number
    except (TypeError, ValueError):
        known = False
    if not known:
        problems.append(Problem(
            "attribute masonryfw_format_version",
            f"unknown format version {_shown(version)}; this masonryfw reads versions "
            f"{', '.join(map(str, READABLE_VERSIONS))} (writes {FORMAT_VERSION}); upgrade masonryfw",
        ))
    return known


def _attribute_problems(ds, schema, kind) -> list[Problem]:
    problems = []
    for name, spec in schema["global_attributes"].items():
        where = f"attribute {name}"
        if name not in ds.attrs:
            if spec.get("required"):
                problems.append(Problem(where, f"missing (required in a {kind} dataset)"))
            continue
        value = ds.attrs[name]
        if name == "masonryfw_format_version":
            continue  # checked first, by _version_is_known
        if name == "masonryfw_format":
            if not _format_attribute_fits(str(value), kind):
                problems.append(Problem(where, f"is {_shown(value)} but a {kind} dataset was expected"))
            continue
        if "value" in spec and str(value) != str(spec["value"]):
            problems.append(Problem(where, f"is {_shown(value)}, must be {_shown(spec['value'])}"))
        if "contains" in spec and spec["contains"] not in str(value).split():
            problems.append(Problem(where, f"is {_shown(value)}, must name {spec['contains']!r}"))
        if "choices" in spec and str(value) not in spec["choices"]:
            problems.append(Problem(where, f"is {_shown(value)}, must be one of {', '.join(map(repr, spec['choices']))}"))
        if spec.get("json"):
            try:
                json.loads(value)
            except (TypeError, ValueError) as err:
                problems.append(Problem(where, f"is not valid JSON ({err})"))
    return problems


def _shown(value) -> str:
    """An attribute value as a reader wants it: strings quoted, numbers plain (no numpy reprs)."""
    if isinstance(value, str):
        return repr(value)
    array = np.asarray(value)
    return str(array.item()) if array.size == 1 else str(array.tolist())


def _format_attribute_fits(stored: str, kind: str) -> bool:
    """The stored kind is ``kind`` or a kind whose schema extends it (a result is also a model)."""
    seen = set()
    while stored in KINDS and stored not in seen:
        if stored == kind:
            return True
        seen.add(stored)
        stored = _raw_extends(stored)
    return False


def _raw_extends(kind: str) -> str:
    return load_schema(kind).get("extends") or ""


def _dimension_problems(ds, schema) -> list[Problem]:
    return [
        Problem(f"dimension {dim}", f"has size {ds.sizes[dim]}, must be {size}")
        for dim, size in schema.get("fixed_sizes", {}).items()
        if dim in ds.sizes and ds.sizes[dim] != size
    ]


def _dtype_class_ok(dtype: np.dtype, wanted: str) -> bool:
    """Integer variables must hold integers; float variables accept integers too (exact in float)."""
    if wanted == "int":
        return np.issubdtype(dtype, np.integer)
    if wanted == "float":
        return np.issubdtype(dtype, np.floating) or np.issubdtype(dtype, np.integer)
    if wanted == "str":
        return dtype.kind in "USO"
    return True


def _variable_structure_problems(ds, schema):
    """Problems with presence, dims, fixed sizes and dtype; and the set of variables safe to read."""
    problems, usable = [], set()
    fixed = schema.get("fixed_sizes", {})
    for name, spec in schema["variables"].items():
        where = f"variable {name}"
        if name not in ds.variables:
            if spec.get("required"):
                problems.append(Problem(where, f"missing (required: {spec['long_name']})"))
            continue
        var = ds[name]
        dims = tuple(spec["dims"])
        if var.dims != dims:
            problems.append(Problem(where, f"has dims {var.dims}, must be {dims}"))
            continue
        if any(dim in fixed and var.sizes[dim] != fixed[dim] for dim in dims):
            continue  # reported once per dimension
        if not _dtype_class_ok(var.dtype, spec["dtype"]):
            problems.append(Problem(where, f"has dtype {var.dtype}, must hold {spec['dtype']} values"))
            continue
        expected_units = spec.get("units")
        units = var.attrs.get("units")
        if units is not None and expected_units is not None and str(units) != expected_units:
            problems.append(Problem(
                where, f"has units {units!r}, the format requires {expected_units!r} (convert the values)"
            ))
        for attr, value in spec.get("attributes", {}).items():
            if var.attrs.get(attr) != value:
                problems.append(Problem(where, f"attribute {attr} is {var.attrs.get(attr)!r}, must be {value!r}"))
        if "values" in spec and [str(v) for v in var.values.ravel()] != list(spec["values"]):
            problems.append(Problem(where, f"holds {list(var.values.ravel())}, must be {spec['values']}"))
        usable.add(name)
    return usable, problems


class _ModelGeometry:
    """Vertices, blocks and interfaces of a dataset whose polygon layout is readable."""

    def __init__(self, x, y, counts, ds, usable):
        self.x, self.y, self.counts = x, y, counts
        self.start = block_offsets(counts)[:-1]
        self.owner = node_block(counts)
        self.next = next_node(counts)
        finite_node = np.isfinite(x) & np.isfinite(y)
        self.tol = RELATIVE_TOLERANCE * model_scale(x[finite_node], y[finite_node])
        finite_block = np.bincount(self.owner, ~finite_node, minlength=counts.size) == 0
        self.readable = finite_block & (counts >= 3)  # polygons the geometry checks look at
        self.area, self.cx, self.cy = polygon_area_centroid(x, y, counts)
        self.nblock = counts.size
        self.interfaces_readable = {"interface_blocks", "interface_x", "interface_y"} <= usable
        if self.interfaces_readable:
            self.if_blocks = ds["interface_blocks"].values.astype(np.int64)
            self.if_x = ds["interface_x"].values.astype(float)
            self.if_y = ds["interface_y"].values.astype(float)
        self.good_polygon = self.readable.copy()  # refined by _polygon_problems
        self.edges_usable = self.readable.copy()  # readable and not self-intersecting (idem)

    @classmethod
    def from_dataset(cls, ds, usable, problems):
        if not {"node_x", "node_y", "block_node_count"} <= usable:
            return None
        counts = ds["block_node_count"].values.astype(np.int64)
        x = ds["node_x"].values.astype(float)
        y = ds["node_y"].values.astype(float)
        if np.any(counts < 0):
            problems.append(Problem("variable block_node_count", "has negative counts: the polygons cannot be read"))
            return None
        if counts.sum() != x.size:
            problems.append(Problem(
                "variable block_node_count",
                f"sums to {int(counts.sum())} vertices but node_x/node_y hold {x.size}: "
                "the polygons cannot be read",
            ))
            return None
        return cls(x, y, counts, ds, usable)

    def block_point(self, b):
        return _point(self.cx[b], self.cy[b])

    def interface_point(self, i):
        if not self.interfaces_readable:
            return None, None
        return _point(self.if_x[i].mean(), self.if_y[i].mean())


def _point(px, py):
    px, py = float(px), float(py)
    return (px, py) if np.isfinite(px) and np.isfinite(py) else (None, None)


def _element_where(dim, index, model):
    """``block 3`` / ``interface 5`` and the point to show, for element ``index`` along ``dim``."""
    if dim == "block":
        return f"block {index}", (model.block_point(index) if model else (None, None))
    if dim == "interface":
        return f"interface {index}", (model.interface_point(index) if model else (None, None))
    if dim == "node" and model is not None:
        return f"block {int(model.owner[index])}", _point(model.x[index], model.y[index])
    return None, (None, None)


def _component(ds, dims, index) -> str:
    """``[uy]``, ``[y]``, ``[side 1]``, ``[end 0]`` for the trailing index of a 2-D variable."""
    if len(dims) < 2:
        return ""
    dim, k = dims[1], index[1]
    if dim == "axis":
        return f"[{'xy'[k]}]"
    if dim in ds.coords and ds.coords[dim].dtype.kind in "USO":
        return f"[{ds.coords[dim].values[k]}]"
    return f"[{dim} {k}]"


def _bound_violations(values, spec):
    """(mask, phrase) pairs for every bound the schema sets on a variable."""
    checks = []
    if "min" in spec:
        checks.append((values < spec["min"], f"is below the minimum {spec['min']:g}"))
    if "min_exclusive" in spec:
        checks.append((values <= spec["min_exclusive"], f"must be greater than {spec['min_exclusive']:g}"))
    if "max" in spec:
        checks.append((values > spec["max"], f"is above the maximum {spec['max']:g}"))
    if "max_exclusive" in spec:
        checks.append((values >= spec["max_exclusive"], f"must be less than {spec['max_exclusive']:g}"))
    if "flag_values" in spec:
        allowed = np.asarray(spec["flag_values"])
        meanings = ", ".join(f"{v}={m}" for v, m in zip(spec["flag_values"], spec["flag_meanings"].split()))
        checks.append((~np.isin(values, allowed), f"is not a valid flag ({meanings})"))
    return checks


def _value_problems(ds, schema, usable, model) -> list[Problem]:
    """Non-finite values, values out of bounds and invalid flags, one problem per element."""
    problems = []
    for name, spec in schema["variables"].items():
        if name not in usable or spec["dtype"] == "str":
            continue
        var = ds[name]
        values = np.asarray(var.values)
        finite = np.isfinite(values) if np.issubdtype(values.dtype, np.floating) else np.ones(values.shape, bool)
        checks = []
        if spec.get("finite"):
            checks.append((~finite, "is not finite"))
        checks += [(mask & finite, phrase) for mask, phrase in _bound_violations(values, spec)]
        for mask, phrase in checks:
            for index in np.argwhere(np.atleast_1d(mask)):
                problems.append(_value_problem(ds, name, spec, values, tuple(index), phrase, model))
    return problems


def _value_problem(ds, name, spec, values, index, phrase, model) -> Problem:
    dims = ds[name].dims
    value = values[index] if dims else values.item()
    where, (px, py) = _element_where(dims[0], int(index[0]), model) if dims else (None, (None, None))
    label = f"{name}{_component(ds, dims, index)}"
    if dims == ("node",) and model is not None:
        label = f"{name} of vertex {index[0]}"
    if where is None:
        where = f"variable {name}"
        if dims:
            label = f"{label} at {dims[0]} {index[0]}"
    return Problem(where, f"{label} = {_format_value(value)} {phrase} ({spec['long_name']})", px, py)


def _format_value(value) -> str:
    value = np.asarray(value).item()
    return f"{value:.6g}" if isinstance(value, float) else str(value)


# ---------------------------------------------------------------- geometry layer

def _polygon_problems(model) -> list[Problem]:
    """Repeated and collinear vertices, self-intersection, area and orientation.

    Each test runs only on the polygons the tests before it let through (a
    self-intersecting polygon has no meaningful area or orientation); the blocks
    passing all of them are kept in ``model.good_polygon`` for the overlap test.
    """
    x, y, owner, tol = model.x, model.y, model.owner, model.tol
    edge_len, offset, forward = vertex_turns(model.x, model.y, model.counts)
    readable_node = model.readable[owner]
    repeated = readable_node & (edge_len <= tol)
    problems = [
        Problem(f"block {owner[v]}", f"vertices {v} and {model.next[v]} coincide (repeated vertex); remove one "
                "(the first vertex is not repeated at the end)", *_point(x[v], y[v]))
        for v in np.flatnonzero(repeated)
    ]
    polygon_ok = model.readable & ~(np.bincount(owner, repeated, minlength=model.nblock) > 0)
    collinear = polygon_ok[owner] & forward & (np.abs(offset) <= tol)
    problems += [
        Problem(f"block {owner[v]}", f"vertex {v} lies on the straight line between its neighbours (zero turn); "
                "remove it", *_point(x[v], y[v]))
        for v in np.flatnonzero(collinear)
    ]
    crossing_blocks, crossing = self_intersections(model.x, model.y, model.counts, polygon_ok, model.tol)
    crossing_points = [_point(px, py) for px, py in crossing]
    problems += [
        Problem(f"block {b}", "the polygon intersects itself (two of its edges meet); reorder the vertices", px, py)
        for b, (px, py) in zip(crossing_blocks, crossing_points)
    ]
    simple = polygon_ok.copy()
    simple[crossing_blocks] = False
    model.edges_usable[crossing_blocks] = False
    perimeter = np.bincount(owner, edge_len, minlength=model.nblock)
    zero_area = simple & (np.abs(model.area) <= tol * perimeter)
    clockwise = simple & ~zero_area & (model.area < 0)
    problems += [
        Problem(f"block {b}", f"zero area ({model.area[b]:.3g} m2): the vertices are (nearly) on one line",
                *model.block_point(b))
        for b in np.flatnonzero(zero_area)
    ]
    problems += [
        Problem(f"block {b}", f"clockwise vertex order (negative area {model.area[b]:.6g} m2); "
                "list the vertices counter-clockwise", *model.block_point(b))
        for b in np.flatnonzero(clockwise)
    ]
    simple &= ~zero_area
    model.good_polygon = simple & ~clockwise
    return problems


def _overlap_problems(model) -> list[Problem]:
    """Blocks that interpenetrate by more than tol (:func:`masonryfw.geometry.overlaps.overlapping_blocks`)."""
    blocks = np.flatnonzero(model.good_polygon)
    p_block, q_block, depth = overlapping_blocks(model.x, model.y, model.counts, blocks, model.tol)
    xmin, xmax, ymin, ymax = block_bounds(model.x, model.y, model.counts)
    problems = []
    for p, q, d in zip(p_block, q_block, depth):
        px_ = 0.5 * (max(xmin[p], xmin[q]) + min(xmax[p], xmax[q]))
        py_ = 0.5 * (max(ymin[p], ymin[q]) + min(ymax[p], ymax[q]))
        problems.append(Problem(
            f"block {p}",
            f"overlaps block {q} (interpenetration {d:.6g} m); move or trim one of them",
            *_point(px_, py_),
        ))
    return problems


def _interface_problems(model) -> list[Problem]:
    """Block indices, zero length, and the segment lying on an edge of both of its blocks."""
    if not model.interfaces_readable:
        return []
    problems = []
    blocks, ix, iy, tol = model.if_blocks, model.if_x, model.if_y, model.tol
    nblock = model.nblock
    in_range = (blocks >= 0) & (blocks < nblock)
    for i, s in np.argwhere(~in_range):
        problems.append(Problem(
            f"interface {i}",
            f"side {s} refers to block {blocks[i, s]}, but the blocks are numbered 0..{nblock - 1}",
            *model.interface_point(i),
        ))
    same = in_range.all(axis=1) & (blocks[:, 0] == blocks[:, 1])
    for i in np.flatnonzero(same):
        problems.append(Problem(
            f"interface {i}", f"both sides are block {blocks[i, 0]}; an interface joins two different blocks",
            *model.interface_point(i),
        ))
    finite_ends = np.isfinite(ix).all(axis=1) & np.isfinite(iy).all(axis=1)
    length = np.hypot(ix[:, 1] - ix[:, 0], iy[:, 1] - iy[:, 0])
    zero = finite_ends & (length <= tol)
    for i in np.flatnonzero(zero):
        problems.append(Problem(
            f"interface {i}", f"zero length ({length[i]:.3g} m); remove it", *model.interface_point(i)
        ))
    testable = finite_ends & ~zero & in_range.all(axis=1) & ~same
    for side in (0, 1):
        rows = np.flatnonzero(testable)
        rows = rows[model.edges_usable[blocks[rows, side]]]
        on_edge = _segment_on_block_edge(model, ix[rows], iy[rows], blocks[rows, side])
        for i in rows[~on_edge]:
            problems.append(Problem(
                f"interface {i}",
                f"segment ({ix[i, 0]:.6g}, {iy[i, 0]:.6g})-({ix[i, 1]:.6g}, {iy[i, 1]:.6g}) does not lie on an "
                f"edge of block {blocks[i, side]} (side {side}); re-detect the interfaces",
                *model.interface_point(i),
            ))
    return problems


def _segment_on_block_edge(model, ix, iy, block):
    """True where both end points lie within tol of one and the same edge of ``block``."""
    if block.size == 0:
        return np.zeros(0, bool)
    edge = carrying_edges(ix, iy, block, model.x, model.y, model.counts)
    ax, ay = model.x[edge], model.y[edge]
    bx, by = model.x[model.next[edge]], model.y[model.next[edge]]
    d0 = point_segment_distance(ix[:, 0], iy[:, 0], ax, ay, bx, by)
    d1 = point_segment_distance(ix[:, 1], iy[:, 1], ax, ay, bx, by)
    return (d0 <= model.tol) & (d1 <= model.tol)


# ---------------------------------------------------------------- mechanics layer

def _connection_problems(ds, usable, model) -> list[Problem]:
    """Blocks that no interface references: a unit touching nothing, a support carrying nothing."""
    if not model.interfaces_readable or model.nblock == 0:
        return []
    blocks = model.if_blocks.ravel()
    blocks = blocks[(blocks >= 0) & (blocks < model.nblock)]
    referenced = np.bincount(blocks, minlength=model.nblock) > 0
    role = ds["block_role"].values if "block_role" in usable else None
    meaning = _flag_meanings("block_role")
    problems = []
    for b in np.flatnonzero(~referenced):
        name = meaning.get(int(role[b]), "block") if role is not None else "block"
        if name.endswith("support"):
            message = f"{name.replace('_', ' ')} carries nothing (no interface references it); remove it or place masonry on it"
        else:
            message = "is connected to nothing (no interface references it): it would fall freely; check its position"
        problems.append(Problem(f"block {b}", message, *model.block_point(b)))
    return problems


def _flag_meanings(variable: str) -> dict[int, str]:
    spec = load_schema("model")["variables"][variable]
    return dict(zip(spec["flag_values"], spec["flag_meanings"].split()))


def _support_problems(ds, usable, model) -> list[Problem]:
    """Settlement directions: non-zero on moving supports (their length is the rate), zero elsewhere."""
    if not {"block_role", "settlement_direction"} <= usable:
        return []
    meaning = _flag_meanings("block_role")
    role = ds["block_role"].values
    direction = ds["settlement_direction"].values.astype(float)
    finite = np.isfinite(direction).all(axis=1)
    norm = np.linalg.norm(np.where(np.isfinite(direction), direction, 0.0), axis=1)
    moving = moving_blocks(role)
    known = np.isin(role, list(meaning))

    def where(b):
        return model.block_point(b) if model is not None else (None, None)

    problems = []
    if role.size and not support_blocks(role).any():
        problems.append(Problem(
            "variable block_role",
            "no support block (fixed_support or moving_support): the wall stands on nothing",
        ))
    for b in np.flatnonzero(moving & finite & (norm == 0)):
        problems.append(Problem(
            f"block {b}",
            "moving support with settlement_direction 0 0 0: it cannot settle; "
            "set e.g. 0 -1 0 for a vertical settlement",
            *where(b),
        ))
    if "block_fixed" in usable:
        held = ds["block_fixed"].values == 1
        clash = moving & finite & np.any(held & (direction != 0), axis=1)
        for b in np.flatnonzero(clash):
            components = [str(c) for c in _dof_labels(ds)[held[b] & (direction[b] != 0)]]
            problems.append(Problem(
                f"block {b}",
                f"block_fixed holds {', '.join(components)} but settlement_direction moves it along "
                f"{'them' if len(components) > 1 else 'it'}; free that component or change the direction",
                *where(b),
            ))
    for b in np.flatnonzero(known & ~moving & finite & (norm > 0)):
        problems.append(Problem(
            f"block {b}",
            f"settlement_direction is non-zero but the block is a {meaning[int(role[b])].replace('_', ' ')}: "
            "only moving supports settle; set it to 0 0 0",
            *where(b),
        ))
    return problems


_RAGGED_3D = (("block_node_count", "node"), ("block_face_count", "face"), ("face_node_count", "face_node"),
              ("interface_node_count", "interface_node"))


def _polyhedron_problems(ds, usable) -> list[Problem]:
    """A 3D model's layout: the ragged counts add up, faces name their own block's vertices, every block is a
    closed polyhedron with its faces outward (a positive volume), every interface joins two blocks over a
    polygon of positive area."""
    problems = [Problem(f"variable {name}", f"adds up to {int(ds[name].values.sum())}, but dimension {dim} has "
                                            f"{ds.sizes.get(dim, 0)}")
                for name, dim in _RAGGED_3D if name in usable and int(ds[name].values.sum()) != ds.sizes.get(dim, 0)]
    layout = {"block_node_count", "block_face_count", "face_node_count", "face_nodes", "node_x", "node_y", "node_z"}
    if problems or not layout <= usable:
        return problems
    poly = polyhedra_of(ds)
    nodes_of_face = np.repeat(poly.block_node_count[poly.face_block()], poly.face_node_count)
    for k in np.flatnonzero(poly.face_nodes >= nodes_of_face)[:1]:
        face = int(np.searchsorted(np.cumsum(poly.face_node_count), k, side="right"))
        problems.append(Problem(f"face {face}", f"names vertex {int(poly.face_nodes[k])} of block "
                                                f"{int(poly.face_block()[face])}, which has {int(nodes_of_face[k])}"))
    if problems:
        return problems
    unmatched = unmatched_edges(poly)
    if unmatched.size:
        face = int(np.searchsorted(np.cumsum(poly.face_node_count), unmatched[0], side="right"))
        problems.append(Problem(f"block {int(poly.face_block()[face])}",
                                f"face {face} has an edge no other face of the block runs the other way "
                                f"({unmatched.size} such edges in the model): the block is not closed, or a face "
                                "is not counter-clockwise seen from outside"))
        return problems
    volume, _ = volumes_centroids(poly)
    for b in np.flatnonzero(~(volume > 0)):
        problems.append(Problem(f"block {b}", f"has volume {volume[b]:.6g} m3: not a closed polyhedron with its "
                                              "faces counter-clockwise seen from outside"))
    if {"interface_blocks", "interface_node_count", "interface_node_x", "interface_node_y",
            "interface_node_z"} <= usable and ds.sizes.get("interface", 0):
        sides = ds["interface_blocks"].values.astype(np.int64).reshape(-1, 2)
        wrong = ((sides < 0) | (sides >= volume.size)).any(axis=1) | (sides[:, 0] == sides[:, 1])
        for i in np.flatnonzero(wrong):
            problems.append(Problem(f"interface {i}", f"joins blocks {sides[i].tolist()}: two different blocks of "
                                                      f"the {volume.size} are needed"))
        _, area = polygon_normals(interface_points(ds), ds["interface_node_count"].values.astype(np.int64))
        for i in np.flatnonzero(~wrong & ~(area > 0)):
            problems.append(Problem(f"interface {i}", "has a polygon of zero area"))
    return problems


def unmatched_edges(poly) -> np.ndarray:
    """The positions in ``face_nodes`` of the face edges (a vertex to the next) that no other face runs back."""
    index = poly.face_vertex_index()
    following = index[next_node(poly.face_node_count)]
    n = poly.vertices.shape[0]
    forward = index * n + following
    backward = following * n + index
    order = np.sort(forward)
    at = np.clip(np.searchsorted(order, backward), 0, max(order.size - 1, 0))
    once = np.searchsorted(order, forward, side="right") - np.searchsorted(order, forward, side="left") == 1
    return np.flatnonzero((order[at] != backward) | ~once) if order.size else np.zeros(0, dtype=np.int64)


def _dof_labels(ds) -> np.ndarray:
    if "dof" in ds.coords:
        return np.asarray([str(v) for v in ds.coords["dof"].values])
    return np.asarray(load_schema("model")["variables"]["dof"]["values"])


def _load_problems(ds, usable) -> list[Problem]:
    if not {"live_load", "live_moment"} <= usable or ds.sizes.get("block", 0) == 0:
        return []
    live = [np.asarray(ds[name].values, dtype=float) for name in ("live_load", "live_moment")]
    if any(np.any(np.isfinite(v) & (v != 0)) for v in live):
        return []
    return [Problem(
        "variable live_load",
        "no live load: the collapse multiplier is undefined; put the settlement load "
        "(downward, on the moving support) or a tilting load in live_load",
    )]

