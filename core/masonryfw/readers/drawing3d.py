"""Blocks drawn in 3D: a Wavefront OBJ file read into closed polyhedra, cleaned and checked.

A block is an object (``o``); in a file without objects, a group (``g``); in a file with neither, each piece
of the mesh whose faces share vertices. A block's layer is the material of its faces (``usemtl``), else the
group it lies in, else ``0``. Only vertices (``v``) and faces (``f``) make geometry; everything else (texture
and normal vertices, lines, smoothing groups) is left out and counted.

Cleaning, in this order: vertices closer than the snap tolerance become one (the first drawn), so a block's
faces meet exactly; repeated vertices in a face are dropped. A face must then keep three vertices or more and
lie in one plane (within the tolerance), and each block must be closed (every edge run by exactly two of its
faces, once each way); a block whose faces all point inwards is turned outward (a note says so). Each error
names the block, its line in the file and the coordinates at fault.
"""
from __future__ import annotations

from pathlib import Path
from typing import NamedTuple

import numpy as np

from ..geometry.polyhedra import Polyhedra, polygon_normals, volumes_centroids
from ..runtime.errors import SpecError
from ..runtime.inputs import fits_in_memory, read_text

#: The largest coordinate of a vertex, in drawing units (10,000 km in millimetres): past it a drawing is not a
#: building, and the snapping's squared distances would overflow.
LARGEST_COORDINATE = 1e10
#: The largest snap tolerance, as a share of the drawing's size.
LARGEST_SNAP = 0.01
#: Memory a face of the drawing takes from its reading to the model (measured: 2.7 kB a face, a 21,600-block
#: mesh of 120,000 faces built in 413 MB at its peak).
BYTES_PER_FACE = 4 * 2**10


class MeshDrawing(NamedTuple):
    """A 3D drawing's blocks: their names, layers and first lines in the file, as closed polyhedra [drawing
    units], and the notes of what cleaning did."""

    names: list[str]
    layers: list[str]
    lines: list[int]
    blocks: Polyhedra
    notes: list[str]


class _Face(NamedTuple):
    nodes: list[int]  # global vertex numbers (0-based)
    line: int
    block: str
    group: str
    material: str


def read_obj(path: Path, snap: float | None) -> MeshDrawing:
    """The blocks of the OBJ file at ``path`` (module docstring); ``snap`` in drawing units (default 1e-6 of the
    drawing's size)."""
    vertices, faces, ignored = _parse(path)
    if not faces:
        raise SpecError(f"drawing {path.name!r}: no faces (f) in it; a 3D drawing is closed polyhedra, one object "
                        "(o) per block")
    far = np.flatnonzero(np.abs(vertices).max(axis=1) > LARGEST_COORDINATE)
    if far.size:
        raise SpecError(f"drawing {path.name!r}: vertex {far[0] + 1} ({', '.join(f'{c:.3g}' for c in vertices[far[0]])})"
                        f" lies beyond {LARGEST_COORDINATE:g} drawing units (10,000 km in mm): is it a mistake, or "
                        "the file not what was meant?")
    size = float(np.ptp(vertices, axis=0).max()) or 1.0
    tol = snap if snap is not None else 1e-6 * size
    if tol > LARGEST_SNAP * size:
        raise SpecError(f"spec key 'geometry.snap_tolerance' = {snap:.3g}: more than {LARGEST_SNAP:g} of the drawing's "
                        f"size ({size:.4g} drawing units): it would make one vertex of the blocks' corners")
    same = _snapped(vertices, tol)
    names, groups = _blocks_of(faces, same)
    notes = [f"{path.name}: {count} {kind} line(s) left out" for kind, count in sorted(ignored.items())]
    parts, layers, lines = [], [], []
    for name, members in groups.items():
        block_faces = [faces[i] for i in members]
        layer = next((f.material for f in block_faces if f.material), "") or next(
            (f.group for f in block_faces if f.group), "0")
        parts.append(_polyhedron(path, name, block_faces, vertices, same, tol, notes))
        layers.append(layer)
        lines.append(block_faces[0].line)
    blocks = Polyhedra(np.concatenate([p[0] for p in parts]), np.array([len(p[0]) for p in parts]),
                       np.array([len(p[1]) for p in parts]), np.concatenate([p[1] for p in parts]),
                       np.concatenate([p[2] for p in parts]))
    return MeshDrawing(names, layers, lines, blocks, notes)


def _parse(path: Path) -> tuple[np.ndarray, list[_Face], dict[str, int]]:
    text = read_text(path, "3D drawing (an OBJ mesh)")  # a regular file of UTF-8, at most TEXT_LIMIT bytes
    faces_in_file = text.count("\nf ") + text.startswith("f ")
    fits_in_memory(faces_in_file * BYTES_PER_FACE, f"drawing {path.name!r} ({faces_in_file:,} faces, about "
                   f"{faces_in_file / 6:,.0f} blocks)", "draw fewer, larger blocks, or a part of the building")
    has_objects = any(line.lstrip().startswith("o ") for line in text.splitlines())
    vertices: list[list[float]] = []
    faces: list[_Face] = []
    ignored: dict[str, int] = {}
    block, group, material = "", "", ""
    for number, raw in enumerate(text.splitlines(), 1):
        words = raw.split("#", 1)[0].split()
        if not words:
            continue
        head, rest = words[0], words[1:]
        if head == "v":
            try:
                vertices.append([float(v) for v in rest[:3]])
            except ValueError:
                vertices.append([])
            if len(vertices[-1]) != 3 or not np.isfinite(vertices[-1]).all():
                raise SpecError(f"drawing {path.name!r} line {number}: {raw.strip()!r} is not a vertex 'v x y z'")
        elif head == "f":
            faces.append(_Face(_face_nodes(path, number, raw, rest, len(vertices)), number,
                               block or (group if not has_objects else ""), group, material))
        elif head == "o":
            block = " ".join(rest) or f"object at line {number}"
        elif head == "g":
            group = " ".join(rest)
        elif head == "usemtl":
            material = " ".join(rest)
        else:
            ignored[head] = ignored.get(head, 0) + 1
    array = np.array(vertices, dtype=float).reshape(-1, 3)
    for face in faces:
        if max(face.nodes) >= len(array):
            raise SpecError(f"drawing {path.name!r} line {face.line}: the face names vertex {max(face.nodes) + 1}, "
                            f"but the file has {len(array)}")
    return array, faces, ignored


def _face_nodes(path: Path, number: int, raw: str, words: list[str], count: int) -> list[int]:
    """A face's vertex numbers, 0-based (OBJ's are 1-based, negative counting back from the last vertex read)."""
    try:
        given = [int(word.split("/")[0]) for word in words]
    except ValueError:
        given = []
    if len(given) < 3 or 0 in given:
        raise SpecError(f"drawing {path.name!r} line {number}: {raw.strip()!r} is not a face of three vertices or "
                        "more 'f i j k ...'")
    nodes = [g - 1 if g > 0 else count + g for g in given]
    if min(nodes) < 0:
        raise SpecError(f"drawing {path.name!r} line {number}: {raw.strip()!r} counts back past the first vertex")
    return nodes


def _snapped(vertices: np.ndarray, tol: float) -> np.ndarray:
    """Every vertex's representative: the first drawn of those within ``tol`` of it (transitively)."""
    from scipy.sparse import coo_matrix  # here, as in the two functions below: building a wall reads no mesh
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    pairs = cKDTree(vertices).query_pairs(tol, output_type="ndarray")
    n = len(vertices)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    first = np.full(label.max() + 1, n)
    np.minimum.at(first, label, np.arange(n))
    return first[label]


def _blocks_of(faces: list[_Face], same: np.ndarray) -> tuple[list[str], dict[str, list[int]]]:
    """The blocks' names and their faces: objects or groups as named; without either, the mesh's pieces."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    if all(face.block for face in faces):
        groups: dict[str, list[int]] = {}
        for i, face in enumerate(faces):
            groups.setdefault(face.block, []).append(i)
        return list(groups), groups
    rows = np.concatenate([np.full(len(face.nodes), i) for i, face in enumerate(faces)])
    nodes = same[np.concatenate([face.nodes for face in faces])]
    incidence = coo_matrix((np.ones(rows.size), (rows, nodes)), shape=(len(faces), same.size)).tocsr()
    _, piece = connected_components(incidence @ incidence.T, directed=False)
    groups = {}
    for i, p in enumerate(piece):
        groups.setdefault(f"piece {p + 1} (from line {faces[int(np.flatnonzero(piece == p)[0])].line})", []).append(i)
    return list(groups), groups


def _polyhedron(path: Path, name: str, faces: list[_Face], vertices: np.ndarray, same: np.ndarray, tol: float,
                notes: list[str]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One block: its vertices, its faces' vertex counts and their nodes numbered within it, closed and outward."""
    where = f"drawing {path.name!r}, block {name!r} (line {faces[0].line})"
    rings = []
    for face in faces:
        ring = [int(v) for v in same[face.nodes]]
        ring = [v for k, v in enumerate(ring) if v != ring[k - 1]]
        if len(ring) < 3:
            raise SpecError(f"{where}: the face at line {face.line} has fewer than three distinct vertices once "
                            f"vertices within {tol:.3g} are one")
        rings.append(ring)
    used = np.unique(np.concatenate(rings))
    local = {int(v): k for k, v in enumerate(used)}
    points = vertices[used]
    edges: dict[tuple[int, int], int] = {}
    face_of_edge: dict[tuple[int, int], int] = {}
    for k, (ring, face) in enumerate(zip(rings, faces)):
        _refuse_bent(points[[local[v] for v in ring]], tol, f"{where}: the face at line {face.line}")
        for a, b in zip(ring, ring[1:] + ring[:1]):
            edges[(a, b)] = edges.get((a, b), 0) + 1
            face_of_edge[(a, b)] = k
    for (a, b), count in edges.items():
        if count != 1 or edges.get((b, a), 0) != 1:
            pa, pb = vertices[a], vertices[b]
            why = "run the same way by two faces (its faces are not turned alike)" if count > 1 else \
                f"bordering {count + edges.get((b, a), 0)} face(s), not two"
            raise SpecError(f"{where}: not a closed solid: the edge from ({', '.join(f'{c:.6g}' for c in pa)}) to "
                            f"({', '.join(f'{c:.6g}' for c in pb)}) is {why}")
    _refuse_separate_solids(where, faces, [(face_of_edge[(a, b)], face_of_edge[(b, a)]) for a, b in face_of_edge])
    counts = np.array([len(r) for r in rings])
    nodes = np.array([local[v] for r in rings for v in r])
    volume = volumes_centroids(Polyhedra(points, np.array([len(points)]), np.array([len(rings)]), counts, nodes))[0][0]
    if abs(volume) <= tol * float(np.ptp(points, axis=0).max()) ** 2:
        raise SpecError(f"{where}: encloses no volume ({volume:.3g})")
    if volume < 0:
        notes.append(f"block {name!r}: its faces pointed inwards; turned outward")
        nodes = np.concatenate([r[::-1] for r in np.split(nodes, np.cumsum(counts)[:-1])])
    return points, counts, nodes


def _refuse_separate_solids(where: str, faces: list[_Face], neighbours: list[tuple[int, int]]) -> None:
    """Refuse a block whose faces make two closed solids or more (one object holding two bricks): its faces are
    one piece when joined across their shared edges."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    pairs = np.array(neighbours, dtype=np.int64).reshape(-1, 2)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(faces), len(faces)))
    count, piece = connected_components(graph, directed=False)
    if count > 1:
        lines = [faces[int(np.flatnonzero(piece == k)[0])].line for k in range(count)]
        raise SpecError(f"{where}: is {count} separate solids (their faces begin at lines "
                        f"{', '.join(map(str, lines))}); a block is one solid: give each its own object (o)")


def _refuse_bent(points: np.ndarray, tol: float, what: str) -> None:
    """Refuse a face whose vertices are not in one plane (within ``tol``)."""
    normal, _ = polygon_normals(points, np.array([len(points)]))
    if not np.any(normal[0]):
        raise SpecError(f"{what}: has no area")
    off = np.abs((points - points.mean(axis=0)) @ normal[0])
    if off.max() > max(tol, 1e-9 * float(np.ptp(points, axis=0).max())):
        worst = points[int(np.argmax(off))]
        raise SpecError(f"{what}: is not planar (vertex ({', '.join(f'{c:.6g}' for c in worst)}) lies "
                        f"{off.max():.3g} off the face's plane); split it into triangles or flat faces")
