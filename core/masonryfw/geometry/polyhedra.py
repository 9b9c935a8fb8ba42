"""Rigid blocks in 3D: polyhedra, their volumes and centroids, and the planar contacts between them.

A set of polyhedra is ragged like the 2D polygons: the vertices of every block one block after another
(``block_node_count``), its faces one after another (``block_face_count``), each face the list of its block's
own vertex numbers (``face_node_count``, ``face_nodes``), counter-clockwise seen from outside. z is up, x and
y are the plan. A face is planar and simple and may be non-convex; a block is closed.

Contacts are found from the faces alone (:func:`find_contacts`): two faces of different blocks touch where
they lie in one plane (within ``tol``) facing each other, over the common part of their polygons (shapely's
intersection in the plane). Each common polygon is an interface; its vertices are the contact points where a
rigid-block programme puts its forces, so that torsion and bending about both axes of the interface come from
where they are.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .boxes import box_pairs
from .polygons import block_offsets, next_node

#: Two faces are parallel when their unit normals differ by less than this (rounded to it).
NORMAL_TOLERANCE = 1e-7


class Polyhedra(NamedTuple):
    """Blocks as polyhedra: their vertices block after block, their faces as lists of the block's own vertex numbers
    (counter-clockwise seen from outside)."""

    vertices: np.ndarray  # (node, 3)
    block_node_count: np.ndarray  # (block,)
    block_face_count: np.ndarray  # (block,)
    face_node_count: np.ndarray  # (face,)
    face_nodes: np.ndarray  # (sum of face_node_count,) the face's vertices, numbered within its block

    @property
    def n_block(self) -> int:
        return self.block_node_count.size

    def face_block(self) -> np.ndarray:
        """The block of every face."""
        return np.repeat(np.arange(self.n_block), self.block_face_count)

    def face_vertex_index(self) -> np.ndarray:
        """Every face's vertices as rows of ``vertices`` (the ragged ``face_nodes`` made global)."""
        first_node = block_offsets(self.block_node_count)[:-1]
        return self.face_nodes + np.repeat(first_node[self.face_block()], self.face_node_count)


class Contacts(NamedTuple):
    """The planar interfaces between polyhedra; the normal points from side 0 into side 1."""

    sides: np.ndarray  # (interface, 2) blocks
    normal: np.ndarray  # (interface, 3) unit
    tangent: np.ndarray  # (interface, 2, 3) two unit tangents, (tangent 0) x (tangent 1) = normal
    point_count: np.ndarray  # (interface,) vertices of the common polygon
    points: np.ndarray  # (sum of point_count, 3) its vertices, counter-clockwise about the normal
    area: np.ndarray  # (interface,)

    @property
    def n_interface(self) -> int:
        return self.sides.shape[0]

    def point_interface(self) -> np.ndarray:
        return np.repeat(np.arange(self.n_interface), self.point_count)


def boxes(lower: np.ndarray, upper: np.ndarray) -> Polyhedra:
    """Axis-aligned boxes from their lower and upper corners ``(block, 3)``."""
    lower, upper = np.atleast_2d(lower).astype(float), np.atleast_2d(upper).astype(float)
    corner = np.array([[i & 1, (i >> 1) & 1, (i >> 2) & 1] for i in range(8)])  # x fastest
    vertices = lower[:, None, :] + corner[None] * (upper - lower)[:, None, :]
    faces = np.array([[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]])
    n = lower.shape[0]  # faces: bottom, top, front (y low), back, left (x low), right; outward counter-clockwise
    return Polyhedra(vertices.reshape(-1, 3), np.full(n, 8), np.full(n, 6), np.full(6 * n, 4), np.tile(faces.ravel(), n))


def prisms(node_x: np.ndarray, node_y: np.ndarray, block_node_count: np.ndarray, thickness: np.ndarray) -> Polyhedra:
    """A wall of 2D polygons (counter-clockwise in x-y, y up) stood in the x-z plane, every block ``thickness`` deep
    about y = 0: the 3D twin of a planar model (its y is 3D's z)."""
    counts = np.asarray(block_node_count, dtype=np.int64)
    first = block_offsets(counts)[:-1]
    block = np.repeat(np.arange(counts.size), counts)
    local = np.arange(counts.sum()) - first[block]  # each vertex's number within its polygon
    count = counts[block]
    half = 0.5 * np.asarray(thickness, dtype=float)[block]
    vertices = np.empty((2 * count.size, 3))
    vertices[2 * first[block] + local] = np.c_[node_x, -half, node_y]  # the front, y = -t/2, then the back
    vertices[2 * first[block] + count + local] = np.c_[node_x, half, node_y]
    following = (local + 1) % count
    sides = np.c_[following, local, count + local, count + following]  # outward, one quad per edge
    front = local  # counter-clockwise in x-z is clockwise seen from -y: the front's outward normal is -y
    back = count + (count - 1 - local)
    per_block = np.concatenate([front, back, sides.ravel()])
    block_of = np.concatenate([block, block, np.repeat(block, 4)])
    part = np.concatenate([np.zeros(count.size), np.ones(count.size), np.full(4 * count.size, 2)])
    order = np.lexsort((np.arange(block_of.size), part, block_of))
    face_counts = np.full(int((counts + 2).sum()), 4, dtype=np.int64)
    first_face = np.cumsum(counts + 2) - (counts + 2)
    face_counts[first_face] = face_counts[first_face + 1] = counts
    return Polyhedra(vertices, 2 * counts, counts + 2, face_counts, per_block[order].astype(np.int64))


def vertical_prisms(node_x: np.ndarray, node_y: np.ndarray, block_node_count: np.ndarray, bottom: np.ndarray,
                    top: np.ndarray) -> Polyhedra:
    """Polygons in plan (counter-clockwise seen from above) extruded from ``bottom`` to ``top`` (per block): the
    planar :func:`prisms` turned a quarter about x, which keeps every face outward."""
    bottom, top = np.asarray(bottom, dtype=float), np.asarray(top, dtype=float)
    stood = prisms(node_x, node_y, block_node_count, top - bottom)
    middle = np.repeat(0.5 * (bottom + top), 2 * np.asarray(block_node_count, dtype=np.int64))
    x, y, z = stood.vertices.T
    return stood._replace(vertices=np.c_[x, z, middle - y])


def joined(*parts: Polyhedra) -> Polyhedra:
    """The blocks of ``parts`` one after another."""
    return Polyhedra(*(np.concatenate([getattr(part, name) for part in parts]) for name in Polyhedra._fields))


def subset(blocks: Polyhedra, keep: np.ndarray) -> Polyhedra:
    """The blocks where the mask ``keep`` is true, in their order."""
    keep = np.asarray(keep, dtype=bool)
    faces = np.repeat(keep, blocks.block_face_count)
    return Polyhedra(blocks.vertices[np.repeat(keep, blocks.block_node_count)], blocks.block_node_count[keep],
                     blocks.block_face_count[keep], blocks.face_node_count[faces],
                     blocks.face_nodes[np.repeat(faces, blocks.face_node_count)])


def polygon_normals(points: np.ndarray, count: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit normals (counter-clockwise vertices: right-handed) and areas of ragged planar polygons."""
    if count.size == 0:
        return np.zeros((0, 3)), np.zeros(0)
    doubled = np.add.reduceat(np.cross(points, points[next_node(count)]), block_offsets(count)[:-1], axis=0)
    length = np.linalg.norm(doubled, axis=1)
    return doubled / np.where(length > 0, length, 1.0)[:, None], 0.5 * length


def face_normals_areas(poly: Polyhedra) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every face's unit outward normal (Newell's, right for non-convex faces), area and centroid."""
    index = poly.face_vertex_index()
    starts = block_offsets(poly.face_node_count)[:-1]
    p, q = poly.vertices[index], poly.vertices[index[next_node(poly.face_node_count)]]
    normal, area = polygon_normals(p, poly.face_node_count)
    anchor = np.repeat(p[starts], poly.face_node_count, axis=0)
    fan = np.einsum("ij,ij->i", np.cross(p - anchor, q - anchor), np.repeat(normal, poly.face_node_count, axis=0))
    doubled_area = np.add.reduceat(fan, starts)
    centre = np.add.reduceat(fan[:, None] * (anchor + p + q), starts, axis=0) / 3.0
    return normal, area, centre / np.where(doubled_area != 0, doubled_area, 1.0)[:, None]


def volumes_centroids(poly: Polyhedra) -> tuple[np.ndarray, np.ndarray]:
    """Every block's volume and centroid: the signed tetrahedra of its faces' fans with its first vertex."""
    index = poly.face_vertex_index()
    starts = block_offsets(poly.face_node_count)[:-1]
    following = next_node(poly.face_node_count)
    block_of_vertex = np.repeat(poly.face_block(), poly.face_node_count)
    first_node = block_offsets(poly.block_node_count)[:-1]
    origin = poly.vertices[first_node][block_of_vertex]
    anchor = np.repeat(poly.vertices[index[starts]], poly.face_node_count, axis=0)
    a, b, c = anchor - origin, poly.vertices[index] - origin, poly.vertices[index[following]] - origin
    six_volume = np.einsum("ij,ij->i", a, np.cross(b, c))
    volume = np.bincount(block_of_vertex, six_volume, minlength=poly.n_block) / 6.0
    moment = np.stack([np.bincount(block_of_vertex, six_volume * (a + b + c)[:, k], minlength=poly.n_block)
                       for k in range(3)], axis=1) / 24.0
    return volume, poly.vertices[first_node] + moment / np.where(volume != 0, volume, 1.0)[:, None]


def second_moments(poly: Polyhedra) -> np.ndarray:
    """``(block, 3, 3)``: every block's ``int (p - c)(p - c)^T dV`` about its centroid ``c``, from the signed
    tetrahedra of its faces' fans (a tetrahedron's is ``V / 20 (sum v v^T + (sum v)(sum v)^T)``)."""
    volume, centroid = volumes_centroids(poly)
    index = poly.face_vertex_index()
    following = next_node(poly.face_node_count)
    starts = block_offsets(poly.face_node_count)[:-1]
    block_of_vertex = np.repeat(poly.face_block(), poly.face_node_count)
    origin = poly.vertices[block_offsets(poly.block_node_count)[:-1]][block_of_vertex] - centroid[block_of_vertex]
    anchor = np.repeat(poly.vertices[index[starts]], poly.face_node_count, axis=0) - centroid[block_of_vertex]
    b = poly.vertices[index] - centroid[block_of_vertex]
    c = poly.vertices[index[following]] - centroid[block_of_vertex]
    six_volume = np.einsum("ij,ij->i", anchor - origin, np.cross(b - origin, c - origin))
    corners = (origin, anchor, b, c)
    total = sum(corners)
    tensor = sum(np.einsum("pi,pj->pij", v, v) for v in corners) + np.einsum("pi,pj->pij", total, total)
    moments = np.zeros((poly.n_block, 3, 3))
    np.add.at(moments, block_of_vertex, (six_volume / 120.0)[:, None, None] * tensor)
    return moments


def plane_frame(normal: np.ndarray) -> np.ndarray:
    """``(n, 2, 3)``: two unit tangents of each unit normal, horizontal first (x for a horizontal plane), with
    (tangent 0) x (tangent 1) = normal."""
    up = np.array([0.0, 0.0, 1.0])
    first = np.cross(up, normal)
    size = np.linalg.norm(first, axis=1)
    first = np.where(size[:, None] > NORMAL_TOLERANCE, first / np.where(size > 0, size, 1.0)[:, None],
                     np.array([1.0, 0.0, 0.0]) * np.sign(normal[:, 2:3] + (normal[:, 2:3] == 0)))
    return np.stack([first, np.cross(normal, first)], axis=1)


def _canonical_planes(normal: np.ndarray, centre: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each face's plane (one number for the faces in one plane within ``tol``, whichever way they face), the
    plane's normal, and +1 / -1 as the face's outward normal is that normal or its opposite."""
    leading = np.argmax(np.abs(normal) > NORMAL_TOLERANCE, axis=1)
    sign = np.sign(normal[np.arange(normal.shape[0]), leading])
    direction = normal * sign[:, None]
    _, group = np.unique(np.round(direction / NORMAL_TOLERANCE).astype(np.int64), axis=0, return_inverse=True)
    group = group.ravel()
    offset = np.einsum("ij,ij->i", direction, centre)
    order = np.lexsort((offset, group))
    new_plane = np.ones(order.size, dtype=bool)
    new_plane[1:] = (group[order][1:] != group[order][:-1]) | (np.diff(offset[order]) > tol)
    plane = np.empty(order.size, dtype=np.int64)
    plane[order] = np.cumsum(new_plane) - 1
    return plane, direction, sign


def find_contacts(poly: Polyhedra, tol: float) -> Contacts:
    """The interfaces of ``poly`` (module docstring): faces of two blocks in one plane within ``tol`` facing each
    other, over a common polygon whose extent in the plane exceeds ``tol`` both ways and whose area exceeds ``tol``
    times its greater extent (two faces meeting along an edge give a polygon of no width)."""
    import shapely

    normal, _, centre = face_normals_areas(poly)
    plane, direction, sign = _canonical_planes(normal, centre, tol)
    block = poly.face_block()
    frame = plane_frame(direction)
    index = poly.face_vertex_index()
    face_of_vertex = np.repeat(np.arange(block.size), poly.face_node_count)
    uv = np.einsum("ij,ikj->ik", poly.vertices[index], frame[face_of_vertex])  # in-plane coordinates
    starts = block_offsets(poly.face_node_count)[:-1]
    low = np.minimum.reduceat(uv, starts, axis=0)
    high = np.maximum.reduceat(uv, starts, axis=0)

    a, b = box_pairs(low, high, -0.5 * tol, plane)  # faces of one plane whose boxes overlap by more than tol
    facing = sign[a] != sign[b]
    a, b = a[facing], b[facing]
    a, b = np.where(sign[a] > 0, a, b), np.where(sign[a] > 0, b, a)  # side 0: the face along the plane's normal
    order = np.lexsort((b, a))  # by the face on side 0, then the other: the interfaces in face order
    a, b = a[order], b[order]
    overlap = np.minimum(high[a], high[b]) - np.maximum(low[a], low[b])
    keep = (block[a] != block[b]) & (overlap > tol).all(axis=1)
    a, b = a[keep], b[keep]
    faces = np.unique(np.concatenate([a, b]))
    polygon = np.empty(block.size, dtype=object)
    polygon[faces] = [shapely.Polygon(uv[starts[f]:starts[f] + poly.face_node_count[f]]) for f in faces]
    common = shapely.intersection(polygon[a], polygon[b])
    parts, pair = shapely.get_parts(common, return_index=True)
    parts = np.asarray(shapely.simplify(parts, 1e-6 * tol))
    polygonal = shapely.get_type_id(parts) == 3
    bounds = shapely.bounds(parts)
    extent = bounds[:, 2:] - bounds[:, :2]
    wide = polygonal & (extent > tol).all(axis=1) & (shapely.area(parts) > tol * extent.max(axis=1, initial=0.0))
    parts, pair = parts[wide], pair[wide]
    return _contacts(parts, a[pair], b[pair], block, direction, frame, centre)


def _contacts(parts, plus_face, minus_face, block, direction, frame, centre) -> Contacts:
    """The interfaces of the common polygons ``parts`` of faces ``plus_face`` (side 0) and ``minus_face``."""
    import shapely

    rings = [np.asarray(shapely.geometry.polygon.orient(p, 1.0).exterior.coords)[:-1] for p in parts]
    holes = [[np.asarray(r.coords)[:-1] for r in p.interiors] for p in parts]
    uv = [np.concatenate([ring, *inner]) for ring, inner in zip(rings, holes)]
    count = np.array([len(points) for points in uv], dtype=np.int64)
    tangent = frame[plus_face]
    normal = direction[plus_face]
    level = 0.5 * (np.einsum("ij,ij->i", normal, centre[plus_face]) + np.einsum("ij,ij->i", normal, centre[minus_face]))
    flat = np.concatenate(uv) if uv else np.zeros((0, 2))
    owner = np.repeat(np.arange(count.size), count)
    points = (level[owner, None] * normal[owner] + flat[:, :1] * tangent[owner, 0] + flat[:, 1:] * tangent[owner, 1])
    area = np.asarray(shapely.area(parts), dtype=float) if len(parts) else np.zeros(0)
    sides = np.c_[block[plus_face], block[minus_face]].astype(np.int64).reshape(-1, 2)
    return Contacts(sides, normal.reshape(-1, 3), tangent.reshape(-1, 2, 3), count, points.reshape(-1, 3), area)


class Overlap(NamedTuple):
    """Two blocks that interpenetrate: how deep (the radius of the largest ball inside both, for convex blocks;
    ``nan`` where one is not convex and a point of one was found inside the other) and the volume they share
    (``nan`` where not convex)."""

    a: int
    b: int
    depth: float
    volume: float
    point: np.ndarray  # (3,) a point inside both


def overlapping_blocks(poly: Polyhedra, tol: float, most: int = 10) -> list[Overlap]:
    """Pairs of blocks of ``poly`` that interpenetrate by more than ``tol`` (two identical blocks, one inside another,
    two laid into one another), at most ``most`` of them. Blocks that touch on a face, an edge or a corner do not.

    The broad phase (:func:`masonryfw.geometry.boxes.box_pairs`) keeps pairs whose boxes overlap by more than ``tol`` on
    every axis: for blocks that are boxes that is the answer. Other pairs are looked at exactly when both blocks
    are convex (the largest ball inside both faces' half-spaces, by a linear programme; the volume of their
    intersection), else by points of one (its vertices, edge and face middles, centroid, each moved ``tol``
    inwards) found inside the other (a winding number)."""
    n = poly.n_block
    owner = np.repeat(np.arange(n), poly.block_node_count)
    low = np.full((n, 3), np.inf)
    high = np.full((n, 3), -np.inf)
    np.minimum.at(low, owner, poly.vertices)
    np.maximum.at(high, owner, poly.vertices)
    a, b = box_pairs(low, high, -0.5 * tol)
    if not a.size:
        return []
    normal, area, centre = face_normals_areas(poly)
    volume, centroid = volumes_centroids(poly)
    is_box = np.abs(volume - np.prod(high - low, axis=1)) <= tol * np.max(high - low, axis=1) ** 2
    face_first = block_offsets(poly.block_face_count)
    found = []
    for p, q in zip(a.tolist(), b.tolist()):
        if is_box[p] and is_box[q]:
            lo, hi = np.maximum(low[p], low[q]), np.minimum(high[p], high[q])
            found.append(Overlap(p, q, 0.5 * float(np.min(hi - lo)), float(np.prod(hi - lo)), 0.5 * (lo + hi)))
        else:
            planes = [(normal[face_first[k]:face_first[k + 1]], centre[face_first[k]:face_first[k + 1]]) for k in (p, q)]
            overlap = _convex_overlap(planes, tol) if all(_convex(poly, k, planes[i], tol) for i, k in
                                                           enumerate((p, q))) else _points_inside(poly, p, q, tol)
            if overlap is not None:
                found.append(Overlap(p, q, *overlap))
        if len(found) >= most:
            break
    return found


def _convex(poly: Polyhedra, block: int, plane: tuple[np.ndarray, np.ndarray], tol: float) -> bool:
    """Whether every vertex of ``block`` lies on the inner side of each of its faces' planes (within ``tol``)."""
    first = block_offsets(poly.block_node_count)
    points = poly.vertices[first[block]:first[block + 1]]
    normal, centre = plane
    return bool(np.all(np.einsum("fj,vj->fv", normal, points) - np.einsum("fj,fj->f", normal, centre)[:, None]
                       <= tol))


def _convex_overlap(planes, tol: float) -> tuple[float, float, np.ndarray] | None:
    """``(depth, volume, point)`` of two convex blocks given by their faces' planes (outward normals, points on
    them) when the largest ball inside both has a radius over ``tol / 2``, else None."""
    from scipy.optimize import linprog
    from scipy.spatial import ConvexHull, HalfspaceIntersection

    normal = np.concatenate([p[0] for p in planes])
    offset = np.einsum("ij,ij->i", normal, np.concatenate([p[1] for p in planes]))
    origin = np.concatenate([p[1] for p in planes]).mean(axis=0)
    offset = offset - normal @ origin  # about the blocks' middle: the programme's numbers stay small
    norms = np.linalg.norm(normal, axis=1)
    ball = linprog(np.r_[0.0, 0.0, 0.0, -1.0], A_ub=np.c_[normal, norms], b_ub=offset,
                   bounds=[(None, None)] * 3 + [(0.0, None)], method="highs")
    if ball.status != 0 or ball.x[3] <= 0.5 * tol:
        return None
    inside = ball.x[:3]
    hull = ConvexHull(HalfspaceIntersection(np.c_[normal, -offset], inside).intersections)
    return float(ball.x[3]), float(hull.volume), inside + origin


def _points_inside(poly: Polyhedra, p: int, q: int, tol: float) -> tuple[float, float, np.ndarray] | None:
    """A point of either block (its vertices, edge and face middles, centroid, each moved ``tol`` towards its
    centroid) inside the other by the winding number of the other's faces; None when there is none."""
    for one, other in ((p, q), (q, p)):
        samples = _samples(poly, one, tol)
        number = winding_numbers(subset(poly, np.arange(poly.n_block) == other), samples)
        inside = np.flatnonzero(number > 0.5)
        if inside.size:
            return float("nan"), float("nan"), samples[inside[0]]
    return None


def _samples(poly: Polyhedra, block: int, tol: float) -> np.ndarray:
    one = subset(poly, np.arange(poly.n_block) == block)
    index = one.face_vertex_index()
    following = index[next_node(one.face_node_count)]
    _, _, face_centre = face_normals_areas(one)
    _, centroid = volumes_centroids(one)
    points = np.concatenate([one.vertices, 0.5 * (one.vertices[index] + one.vertices[following]), face_centre,
                             centroid])
    towards = centroid[0] - points
    length = np.linalg.norm(towards, axis=1)
    return points + towards * (np.minimum(tol, length) / np.where(length > 0, length, 1.0))[:, None]


def winding_numbers(poly: Polyhedra, points: np.ndarray) -> np.ndarray:
    """How many times the closed surface of ``poly``'s faces winds around each of ``points``: 1 inside a block, 0
    outside (the solid angles of the faces' fan triangles, Van Oosterom and Strackee, over 4 pi)."""
    index = poly.face_vertex_index()
    starts = block_offsets(poly.face_node_count)[:-1]
    apex = np.repeat(index[starts], poly.face_node_count - 2)
    keep = np.ones(index.size, dtype=bool)
    keep[starts] = False
    keep[block_offsets(poly.face_node_count)[1:] - 1] = False
    second = index[keep]
    third = index[np.flatnonzero(keep) + 1]
    total = np.zeros(len(points))
    for tri in np.array_split(np.arange(apex.size), max(1, apex.size // 4096)):
        r = [poly.vertices[corner[tri]][None] - points[:, None] for corner in (apex, second, third)]
        size = [np.linalg.norm(v, axis=2) for v in r]
        top = np.einsum("ptj,ptj->pt", r[0], np.cross(r[1], r[2]))
        bottom = (size[0] * size[1] * size[2] + np.einsum("ptj,ptj->pt", r[0], r[1]) * size[2]
                  + np.einsum("ptj,ptj->pt", r[1], r[2]) * size[0] + np.einsum("ptj,ptj->pt", r[2], r[0]) * size[1])
        total += 2.0 * np.arctan2(top, bottom).sum(axis=1)
    return total / (4.0 * np.pi)
