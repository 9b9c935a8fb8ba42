"""The ``jmm`` solves' time and peak memory, known before they start (``Solver.estimate``).

The degrees of freedom follow from the mesh's cells (two triangles each: about 8 DOFs a
cell with quadratic elements, 2 with linear ones), counted on the grid lines of an
axis-aligned wall, else from the masonry's area and its blocks' perimeters (gmsh refines
along the sides of small blocks). The time constants are fitted on the 2-core VM of docs/benchmarks.md on an
Intel Xeon host (2026-11-28): a Newton iteration costs 0.27 s at 131,566 DOFs (the 1,035-block scale wall: 594
iterations in 161 s) and grows as DOFs^1.35 (the 2,432-block paper wall, 308,962 DOFs: 495 iterations in
413-428 s); the same VM on an AMD EPYC host ran them 1.55x faster (104 s; 2026-11-25) and fdem 1.5x slower,
so an estimate is good to its host. A run to the plateau takes 200-600 iterations on the bundled and scale
walls (500 assumed). On a busy machine the time is divided by the share of a core the run gets
(``mfp.core_share``): the 1,035-block wall beside two spinning processes took 276 s, estimated 199 s (133 s
without the share). Memory is 5 kB a DOF over the interpreter's 200 MiB (the factor's fill).
The limit LP (``jmm-limit``) is one interior-point solve of a 2-3x larger programme.
"""
from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr

import masonryfw.plugin_api as mfp

from .mesh import axis_aligned, block_boxes, grid_lines, masonry

DOFS_PER_CELL = {"p2": 8.0, "p1": 2.0}
UNSTRUCTURED_CELLS = 1.15  # gmsh's triangles of side mesh_size, in cells (two triangles) per mesh_size^2
UNSTRUCTURED_EDGE_DOFS = 4.5  # the finer cells along block sides: DOFs per mesh_size of perimeter (fitted on
# arch-settlement, lact3-arch and lact3-portal: 3.2-7.2)
ITERATION_SECONDS = 0.27  # 1,035 blocks: 594 Newton iterations in 161 s (nested-dissection ordering)
ITERATION_DOFS = 131_566
TIME_EXPONENT = 1.35
NEWTON_ITERATIONS = 500
LIMIT_LP_SECONDS = 11.5  # Facade 3 at the default mesh, 65,664 LP variables (about 2.2 a DOF)
LIMIT_LP_DOFS = 30_170
BASE_MEMORY = 200 * 2**20
MEMORY_PER_DOF = 5e3
LIMIT_MEMORY_PER_DOF = 12e3


def structured_cells(model: xr.Dataset, size: float) -> int:
    """The cells of :func:`.mesh.structured_mesh`, counted on its grid lines without building it."""
    box = block_boxes(model)[masonry(model)]
    tol = 1e-9 * mfp.model_scale(model.node_x.values, model.node_y.values)
    xs = grid_lines(box[:, [0, 2]].ravel(), size, tol)
    ys = grid_lines(box[:, [1, 3]].ravel(), size, tol)
    across = np.searchsorted(xs, box[:, 2] - tol) - np.searchsorted(xs, box[:, 0] - tol)
    up = np.searchsorted(ys, box[:, 3] - tol) - np.searchsorted(ys, box[:, 1] - tol)
    return int((across * up).sum())


def mesh_dofs(model: xr.Dataset, options: Mapping[str, Any], element: str = "p2") -> tuple[int, float]:
    """``(DOFs, mesh size)`` of the mesh ``options`` ask for: its cells counted on the grid of an axis-aligned
    wall, else the masonry's area over the cell area (gmsh's triangles of side ``size``: about 1.15 cells)."""
    from .problem import auto_mesh_size

    size = options["mesh_size"] if options["mesh_size"] is not None else auto_mesh_size(model)
    per_cell = DOFS_PER_CELL[element]
    if axis_aligned(model):
        return int(per_cell * structured_cells(model, size)), size
    blocks = masonry(model)
    cells = UNSTRUCTURED_CELLS * float(model.block_area.values[blocks].sum()) / size**2
    edges = UNSTRUCTURED_EDGE_DOFS * per_cell / 8 * masonry_perimeter(model, blocks) / size
    return int(per_cell * cells + edges), size


def masonry_perimeter(model: xr.Dataset, blocks: np.ndarray) -> float:
    """The summed perimeters of ``blocks``."""
    x, y = model.node_x.values, model.node_y.values
    start = mfp.block_offsets(model.block_node_count.values)
    following = np.arange(x.size) + 1
    following[start[1:] - 1] = start[:-1]  # each block's last node closes on its first
    sides = np.hypot(x[following] - x, y[following] - y)
    return float(sum(sides[start[b]:start[b + 1]].sum() for b in blocks))


def advice(size: float) -> str:
    return f"a larger --option mesh_size (now {size:.3g} m; the DOFs grow as 1 / mesh_size^2)"


def estimate(model: xr.Dataset, options: Mapping[str, Any]) -> mfp.Estimate:
    dofs, size = mesh_dofs(model, options, options["element"])
    seconds = NEWTON_ITERATIONS * ITERATION_SECONDS * (dofs / ITERATION_DOFS) ** TIME_EXPONENT \
        / mfp.core_share(mfp.cores(), mfp.machine_load())
    return mfp.Estimate(seconds=seconds, memory=BASE_MEMORY + MEMORY_PER_DOF * dofs,
                       basis=f"about {dofs:,} DOFs and {NEWTON_ITERATIONS} Newton iterations, as fitted on the 2-core "
                             "machine of docs/benchmarks.md", advice=advice(size))


def estimate_limit(model: xr.Dataset, options: Mapping[str, Any]) -> mfp.Estimate:
    dofs, size = mesh_dofs(model, options)  # the mesh's size in P2 DOFs, the unit its constants are fitted in
    seconds = LIMIT_LP_SECONDS * (dofs / LIMIT_LP_DOFS) ** 1.4
    return mfp.Estimate(seconds=seconds, memory=BASE_MEMORY + LIMIT_MEMORY_PER_DOF * dofs,
                       basis=f"about {dofs:,} DOFs, as fitted on the 2-core machine of docs/benchmarks.md",
                       advice=advice(size))
