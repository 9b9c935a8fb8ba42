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

from .dofs import upgrade
from .geometry import (
    block_bounds,
    block_offsets,
    carrying_edges,
    convex_pieces,
    model_scale,
    next_node,
    node_block,
    point_segment_distance,
    polygon_area_centroid,
    vertex_turns,
)
from .schema import FORMAT_VERSION, KINDS, READABLE_VERSIONS, load_schema

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
    format version is checked as it reads (upgraded, :func:`masonryfw.dofs.upgrade`).
    ``model_checked=True`` checks only what a result adds to a model already
    checked (its variables' format and its attributes), as :func:`masonryfw.solve`
    does with what a solver returned.
    """
    problems: list[Problem] = []
    kind = _dataset_kind(ds, kind, problems)
    if kind is None or not _version_is_known(ds, problems):
        return problems
    ds = upgrade(ds)
    schema = load_schema(kind)
    if model_checked:
        return _added_variable_problems(ds, schema, kind)
    problems += _attribute_problems(ds, schema, kind)
    problems += _dimension_problems(ds, schema)
    usable, structure = _variable_structure_problems(ds, schema)
    problems += structure
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


def _added_variable_problems(ds, schema, kind) -> list[Problem]:
    """The format layer for the variables a result adds to its (checked) model."""
    model_variables = load_schema("model")["variables"]
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
    crossing_blocks, crossing_points = _self_intersections(model, polygon_ok)
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


def _segment_distance(p0x, p0y, p1x, p1y, q0x, q0y, q1x, q1y):
    """Shortest distance between segments p and q (0 when they cross), and a point near the contact."""
    def side(ax, ay, bx, by, cx, cy):
        return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)

    d1 = side(q0x, q0y, q1x, q1y, p0x, p0y)
    d2 = side(q0x, q0y, q1x, q1y, p1x, p1y)
    d3 = side(p0x, p0y, p1x, p1y, q0x, q0y)
    d4 = side(p0x, p0y, p1x, p1y, q1x, q1y)
    crosses = (d1 * d2 < 0) & (d3 * d4 < 0)
    candidates = [  # (distance of an end point from the other segment, that end point)
        (point_segment_distance(p0x, p0y, q0x, q0y, q1x, q1y), p0x, p0y),
        (point_segment_distance(p1x, p1y, q0x, q0y, q1x, q1y), p1x, p1y),
        (point_segment_distance(q0x, q0y, p0x, p0y, p1x, p1y), q0x, q0y),
        (point_segment_distance(q1x, q1y, p0x, p0y, p1x, p1y), q1x, q1y),
    ]
    dist = np.stack([c[0] for c in candidates])
    which = np.argmin(dist, axis=0)
    near_x = np.choose(which, [c[1] for c in candidates])
    near_y = np.choose(which, [c[2] for c in candidates])
    with np.errstate(invalid="ignore", divide="ignore"):
        t = d1 / (d1 - d2)
        cross_x = p0x + t * (p1x - p0x)
        cross_y = p0y + t * (p1y - p0y)
    distance = np.where(crosses, 0.0, dist.min(axis=0))
    return distance, np.where(crosses, cross_x, near_x), np.where(crosses, cross_y, near_y)


def _self_intersections(model, candidates):
    """Blocks (among ``candidates``) two of whose non-adjacent edges come within tol, and where.

    Blocks are grouped by vertex count; within a group all non-adjacent edge
    pairs of all blocks are tested at once (k(k-3)/2 pairs for k vertices).
    """
    blocks_out, points_out = [], []
    for k in np.unique(model.counts[candidates]):
        if k < 4:
            continue  # a triangle has no non-adjacent edges
        blocks = np.flatnonzero(candidates & (model.counts == k))
        idx = model.start[blocks][:, None] + np.arange(k)[None, :]
        i, j = np.triu_indices(k, 2)
        keep = ~((i == 0) & (j == k - 1))
        i, j = i[keep], j[keep]
        vx, vy = model.x[idx], model.y[idx]
        wx, wy = np.roll(vx, -1, axis=1), np.roll(vy, -1, axis=1)
        dist, px, py = _segment_distance(
            vx[:, i], vy[:, i], wx[:, i], wy[:, i], vx[:, j], vy[:, j], wx[:, j], wy[:, j]
        )
        hit = dist <= model.tol
        rows = np.flatnonzero(hit.any(axis=1))
        first = np.argmax(hit[rows], axis=1)
        blocks_out += blocks[rows].tolist()
        points_out += [_point(px[r, c], py[r, c]) for r, c in zip(rows, first)]
    order = np.argsort(blocks_out, kind="stable")
    return np.asarray(blocks_out, dtype=np.int64)[order], [points_out[o] for o in order]


def _ragged_expand(counts):
    """For rows with ``counts`` items each: the row of every item and its position in the row."""
    counts = np.asarray(counts, dtype=np.int64)
    row = np.repeat(np.arange(counts.size), counts)
    position = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    return row, position


def _candidate_block_pairs(xmin, xmax, ymin, ymax, blocks, tol):
    """Pairs (a < b) of ``blocks`` whose bounding boxes, shrunk by tol, overlap; by a uniform grid.

    Each block is entered in every grid cell its shrunk box covers; pairs are
    formed only inside a cell, so the work grows with the number of blocks
    rather than its square.
    """
    if blocks.size < 2:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    x0, x1 = xmin[blocks] + tol, xmax[blocks] - tol
    y0, y1 = ymin[blocks] + tol, ymax[blocks] - tol
    cell = float(np.median(np.maximum(x1 - x0, y1 - y0)))
    cell = cell if cell > 0 else 1.0
    gx0, gy0 = x0.min(), y0.min()
    ix0, ix1 = np.floor((x0 - gx0) / cell).astype(np.int64), np.floor((x1 - gx0) / cell).astype(np.int64)
    iy0, iy1 = np.floor((y0 - gy0) / cell).astype(np.int64), np.floor((y1 - gy0) / cell).astype(np.int64)
    ix1, iy1 = np.maximum(ix1, ix0), np.maximum(iy1, iy0)
    nx_cells = int(ix1.max()) + 1
    wide, high = ix1 - ix0 + 1, iy1 - iy0 + 1
    row, pos = _ragged_expand(wide * high)
    cell_id = (iy0[row] + pos // wide[row]) * nx_cells + ix0[row] + pos % wide[row]
    order = np.lexsort((row, cell_id))
    member, cell_id = row[order], cell_id[order]
    group_start = np.flatnonzero(np.concatenate(([True], np.diff(cell_id) != 0)))
    group_end = np.append(group_start[1:], cell_id.size)
    size = group_end - group_start
    end_of = np.repeat(group_end, size)
    partners = end_of - np.arange(cell_id.size) - 1
    left, offset = _ragged_expand(partners)
    right = left + 1 + offset
    a, b = member[left], member[right]
    a, b = np.minimum(a, b), np.maximum(a, b)
    key = np.sort(a * blocks.size + b)  # sort + diff: faster than np.unique's hashing here
    key = key[np.concatenate(([True], np.diff(key) != 0))]
    a, b = key // blocks.size, key % blocks.size
    boxes_meet = (x0[a] < x1[b]) & (x0[b] < x1[a]) & (y0[a] < y1[b]) & (y0[b] < y1[a])
    return blocks[a[boxes_meet]], blocks[b[boxes_meet]]


@dataclass(frozen=True)
class _Polygons:
    """Convex polygons in the ragged layout, for the separating-axis test."""

    x: np.ndarray
    y: np.ndarray
    counts: np.ndarray
    owner: np.ndarray  # block of every polygon

    @property
    def start(self) -> np.ndarray:
        return block_offsets(self.counts)[:-1]

    @property
    def next(self) -> np.ndarray:
        return next_node(self.counts)


def _penetration(pieces: _Polygons, a, b):
    """Separating-axis depth of convex counter-clockwise polygon b into a, over a's edge normals.

    For each edge of ``a`` (outward unit normal n, support value h = n . edge
    start) the depth is ``h - min_j n . q_j`` over the vertices q of ``b``; the
    polygons overlap by at most the smallest of these (<= 0: separated or touching).
    """
    x, y, nxt, start, counts = pieces.x, pieces.y, pieces.next, pieces.start, pieces.counts
    pair, k = _ragged_expand(counts[a])
    edge = start[a][pair] + k
    ex, ey = x[nxt[edge]] - x[edge], y[nxt[edge]] - y[edge]
    length = np.hypot(ex, ey)
    nx, ny = ey / length, -ex / length
    h = nx * x[edge] + ny * y[edge]
    row, j = _ragged_expand(counts[b][pair])
    vertex = start[b][pair][row] + j
    projection = nx[row] * x[vertex] + ny[row] * y[vertex]
    row_start = np.concatenate(([0], np.cumsum(counts[b][pair])[:-1]))
    depth_per_edge = h - np.minimum.reduceat(projection, row_start)
    pair_start = np.concatenate(([0], np.cumsum(counts[a])[:-1]))
    return np.minimum.reduceat(depth_per_edge, pair_start)


def _overlap_problems(model) -> list[Problem]:
    """Blocks that interpenetrate by more than tol (bounding-box grid, then separating axes).

    Non-convex blocks are tested through their convex pieces (:func:`convex_pieces`);
    two blocks overlap by the deepest overlap of any two of their pieces.
    """
    blocks = np.flatnonzero(model.good_polygon)
    if blocks.size < 2:
        return []
    nodes = np.repeat(model.start[blocks], model.counts[blocks]) + _ragged_expand(model.counts[blocks])[1]
    px, py, pc, owner = convex_pieces(model.x[nodes], model.y[nodes], model.counts[blocks], model.tol)
    pieces = _Polygons(px, py, pc, blocks[owner])
    everyone = np.arange(pc.size)
    bounds = block_bounds(px, py, pc)
    a, b = _candidate_block_pairs(*bounds, everyone, model.tol)
    other = pieces.owner[a] != pieces.owner[b]
    a, b = a[other], b[other]
    if a.size == 0:
        return []
    depth = np.minimum(_penetration(pieces, a, b), _penetration(pieces, b, a))
    overlapping = depth > model.tol
    p_block = np.minimum(pieces.owner[a], pieces.owner[b])[overlapping]
    q_block = np.maximum(pieces.owner[a], pieces.owner[b])[overlapping]
    depth = depth[overlapping]
    if depth.size == 0:
        return []
    order = np.lexsort((-depth, q_block, p_block))
    first = np.concatenate(([True], (np.diff(p_block[order]) != 0) | (np.diff(q_block[order]) != 0)))
    problems = []
    xmin, xmax, ymin, ymax = block_bounds(model.x, model.y, model.counts)
    for p, q, d in zip(p_block[order][first], q_block[order][first], depth[order][first]):
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
    moving_flag = next(v for v, m in meaning.items() if m == "moving_support")
    role = ds["block_role"].values
    direction = ds["settlement_direction"].values.astype(float)
    finite = np.isfinite(direction).all(axis=1)
    norm = np.linalg.norm(np.where(np.isfinite(direction), direction, 0.0), axis=1)
    moving = role == moving_flag
    known = np.isin(role, list(meaning))

    def where(b):
        return model.block_point(b) if model is not None else (None, None)

    problems = []
    supports = [v for v, m in meaning.items() if m.endswith("support")]
    if role.size and not np.isin(role, supports).any():
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

