"""Hand-made models and results for the compare plugin's tests.

The model is a stack-bonded grid wall (``rows`` x ``cols`` units of b x h) on two
support blocks: a fixed one under the first ``split`` columns and a moving one
under the rest. Interfaces are written out by hand (head, bed and support joints),
so every count and coordinate below is known without running the core.
Results follow FORMAT.md ("Result variables") for three kinds of solver:
limit analysis (LA), FEM/DEM and a continuum (JMM).
"""
from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest
import xarray as xr

import masonryfw as mf

B, H = 0.2, 0.1  # unit length and height [m]
WEIGHT = 12e3  # N m-3
THICKNESS = 0.1


def _attrs(name: str) -> dict:
    return mf.variable_attrs(name)


def _rectangles(x0, x1, y0, y1):
    """Counter-clockwise vertices of rectangles, block after block."""
    x = np.column_stack([x0, x1, x1, x0]).ravel()
    y = np.column_stack([y0, y0, y1, y1]).ravel()
    return x, y


def grid_model(rows: int = 4, cols: int = 6, split: int = 3, title: str = "Grid wall") -> xr.Dataset:
    """A valid model dataset: units ``r * cols + c``, then the fixed and the moving support."""
    r, c = np.divmod(np.arange(rows * cols), cols)
    sx0 = np.array([0.0, split * B])
    sx1 = np.array([split * B, cols * B])
    x, y = _rectangles(
        np.concatenate([c * B, sx0]), np.concatenate([(c + 1) * B, sx1]),
        np.concatenate([r * H, [-H, -H]]), np.concatenate([(r + 1) * H, [0.0, 0.0]]),
    )
    nblock = rows * cols + 2
    fixed, moving = rows * cols, rows * cols + 1
    role = np.zeros(nblock, dtype=np.int8)
    role[fixed], role[moving] = 2, 3

    # head joints: left block is side 0 (n = +x), end 0 on top (t = (0, -1))
    hr, hc = np.divmod(np.arange(rows * (cols - 1)), cols - 1)
    head_blocks = np.column_stack([hr * cols + hc, hr * cols + hc + 1])
    head_x = np.column_stack([(hc + 1) * B, (hc + 1) * B])
    head_y = np.column_stack([(hr + 1) * H, hr * H])
    # bed joints: lower block is side 0 (n = +y), end 0 on the left (t = (1, 0))
    br, bc = np.divmod(np.arange((rows - 1) * cols), cols)
    bed_blocks = np.column_stack([br * cols + bc, (br + 1) * cols + bc])
    bed_x = np.column_stack([bc * B, (bc + 1) * B])
    bed_y = np.column_stack([(br + 1) * H, (br + 1) * H])
    # support joints under the first course
    sc = np.arange(cols)
    sup_blocks = np.column_stack([np.where(sc < split, fixed, moving), sc])
    sup_x = np.column_stack([sc * B, (sc + 1) * B])
    sup_y = np.zeros((cols, 2))

    blocks = np.concatenate([head_blocks, bed_blocks, sup_blocks])
    kind = np.concatenate([np.full(len(head_blocks), 1), np.zeros(len(bed_blocks)), np.full(cols, 2)]).astype(np.int8)
    nint = len(blocks)

    unit_weight = np.where(role < 2, WEIGHT, 0.0)
    total = WEIGHT * THICKNESS * B * H * rows * cols
    share = total * (cols - split) / cols
    dead = np.zeros((nblock, 3))
    dead[: rows * cols, 1] = -WEIGHT * THICKNESS * B * H
    dead[moving, 1] = share
    live = np.zeros((nblock, 3))
    live[moving, 1] = -share
    block_fixed = np.zeros((nblock, 3), dtype=np.int8)
    block_fixed[fixed] = 1
    block_fixed[moving] = [1, 0, 1]
    direction = np.zeros((nblock, 3))
    direction[moving, 1] = -1.0

    def var(dims, values, name):
        return (dims, values, _attrs(name))

    return xr.Dataset(
        {
            "node_x": var("node", x, "node_x"),
            "node_y": var("node", y, "node_y"),
            "block_node_count": var("block", np.full(nblock, 4, dtype=np.int32), "block_node_count"),
            "block_role": var("block", role, "block_role"),
            "block_thickness": var("block", np.full(nblock, THICKNESS), "block_thickness"),
            "block_unit_weight": var("block", unit_weight, "block_unit_weight"),
            "interface_blocks": var(("interface", "side"), blocks.astype(np.int32), "interface_blocks"),
            "interface_x": var(("interface", "end"), np.concatenate([head_x, bed_x, sup_x]), "interface_x"),
            "interface_y": var(("interface", "end"), np.concatenate([head_y, bed_y, sup_y]), "interface_y"),
            "interface_kind": var("interface", kind, "interface_kind"),
            "interface_friction": var("interface", np.full(nint, 0.4), "interface_friction"),
            "interface_cohesion": var("interface", np.zeros(nint), "interface_cohesion"),
            "interface_tensile_strength": var("interface", np.zeros(nint), "interface_tensile_strength"),
            "dead_load": var(("block", "dof"), dead, "dead_load"),
            "live_load": var(("block", "dof"), live, "live_load"),
            "block_fixed": var(("block", "dof"), block_fixed, "block_fixed"),
            "settlement_direction": var(("block", "dof"), direction, "settlement_direction"),
        },
        coords={"dof": ("dof", np.array(["ux", "uy", "rz"]))},
        attrs={
            "Conventions": "CF-1.11",
            "masonryfw_format": "model",
            "masonryfw_format_version": 1,
            "title": title,
        },
    )


def head_line(model: xr.Dataset, column: int) -> np.ndarray:
    """Mask of the head joints on the vertical line x = column * B (all courses)."""
    is_head = model.interface_kind.values == 1
    on_line = np.isclose(model.interface_x.values[:, 0], column * B)
    return is_head & on_line


def unit_column(model: xr.Dataset) -> np.ndarray:
    """Column index of every block (supports: -1)."""
    cols = int(round(np.ptp(model.node_x.values) / B))
    n_units = int((model.block_role.values < 2).sum())
    return np.concatenate([np.arange(n_units) % cols, [-1, -1]])


def _result_attrs(model: xr.Dataset, solver: str, options: dict) -> dict:
    return {
        **model.attrs,
        "masonryfw_format": "result",
        "plugin": solver,
        "plugin_version": "0",
        "solver": solver,
        "solver_options": json.dumps(options),
        "wall_time_s": 0.01,
    }


def _translation_mechanism(model: xr.Dataset, first_moving_column: int) -> np.ndarray:
    """Units of columns >= first_moving_column and the moving support go down by 1."""
    column = unit_column(model)
    u = np.zeros((model.sizes["block"], 3))
    u[column >= first_moving_column, 1] = -1.0
    u[model.block_role.values == 3, 1] = -1.0
    return u


def _relative_translation(model: xr.Dataset, u: np.ndarray):
    """Opening and slip per interface end for translating blocks (same at both ends)."""
    geo = mf.derive_geometry(model)
    blocks = model.interface_blocks.values
    dv = u[blocks[:, 1], :2] - u[blocks[:, 0], :2]
    opening = dv[:, 0] * geo.interface_normal_x.values + dv[:, 1] * geo.interface_normal_y.values
    slip = dv[:, 0] * geo.interface_tangent_x.values + dv[:, 1] * geo.interface_tangent_y.values
    return np.repeat(opening[:, None], 2, axis=1), np.repeat(slip[:, None], 2, axis=1)


def la_result(model: xr.Dataset, first_moving_column: int = 3, cracked=None, backend: str = "highs") -> xr.Dataset:
    """A limit-analysis result: the units right of a vertical crack translate down with the support.

    ``cracked`` (interface mask) defaults to every joint whose blocks move apart.
    """
    u = _translation_mechanism(model, first_moving_column)
    opening, slip = _relative_translation(model, u)
    moving_apart = (np.abs(opening).max(axis=1) > 0) | (np.abs(slip).max(axis=1) > 0)
    cracked = moving_apart if cracked is None else np.asarray(cracked, dtype=bool)
    state = np.where(opening.max(axis=1) > 0, 1, 0) + np.where(np.abs(slip).max(axis=1) > 0, 2, 0)
    normal = np.where(np.arange(model.sizes["interface"])[:, None] % 3 == 0, [[1.0, 3.0]], [[2.0, 2.0]]) * 10.0
    macro = np.where(u[:, 1] < 0, 1, 0)
    return model.assign(
        collapse_multiplier=((), 0.3, _attrs("collapse_multiplier")),
        block_displacement=(("block", "dof"), u, _attrs("block_displacement")),
        interface_opening=(("interface", "end"), opening, _attrs("interface_opening")),
        interface_slip=(("interface", "end"), slip, _attrs("interface_slip")),
        interface_normal_force=(("interface", "end"), normal, _attrs("interface_normal_force")),
        interface_shear_force=(("interface", "end"), 0.2 * normal, _attrs("interface_shear_force")),
        interface_state=("interface", np.where(cracked, state, 0).astype(np.int8), _attrs("interface_state")),
        crack_indicator=("interface", cracked.astype(float), _attrs("crack_indicator")),
        macro_block=("block", macro.astype(np.int32), _attrs("macro_block")),
    ).assign_attrs(_result_attrs(model, "la", {"solver": backend}))


def fdem_result(model: xr.Dataset, first_moving_column: int = 3) -> xr.Dataset:
    """An incremental discrete result: 5 mm final settlement, reaction history, no forces or states."""
    u = 0.005 * _translation_mechanism(model, first_moving_column)
    steps = np.linspace(0.0, 0.005, 11)
    crack = head_line(model, first_moving_column).astype(float)
    return model.assign(
        block_displacement=(("block", "dof"), u, _attrs("block_displacement")),
        crack_indicator=("interface", crack, _attrs("crack_indicator")),
        macro_block=("block", np.where(u[:, 1] < 0, 1, 0).astype(np.int32), _attrs("macro_block")),
        step_settlement=("step", steps, _attrs("step_settlement")),
        step_reaction=("step", 100.0 * np.exp(-steps / 0.001), _attrs("step_reaction")),
    ).assign_attrs(_result_attrs(model, "fdem", {}))


def jmm_result(
    model: xr.Dataset, crack_column: int = 3, per_unit: int = 2, offset: float = 0.0, tensile_top: bool = True
) -> xr.Dataset:
    """A continuum result on a quad mesh over the wall, one quadrature point per face.

    The faces whose centre lies within half a face width of the line
    x = crack_column * B + offset are plastic in shear; the top row is tensile
    (with ``tensile_top``).
    The crack indicator maps the failure onto the head joints of that line.
    """
    cols = int(round(np.ptp(model.node_x.values) / B))
    rows = int(round(model.node_y.values.max() / H))
    nx, ny = cols * per_unit, rows * per_unit
    gx, gy = np.meshgrid(np.linspace(0, cols * B, nx + 1), np.linspace(0, rows * H, ny + 1))
    node = np.arange((nx + 1) * (ny + 1)).reshape(ny + 1, nx + 1)
    faces = np.stack([node[:-1, :-1], node[:-1, 1:], node[1:, 1:], node[1:, :-1]], axis=-1).reshape(-1, 4)
    qx = gx.ravel()[faces].mean(axis=1)
    qy = gy.ravel()[faces].mean(axis=1)
    dx = B / per_unit
    failure = np.zeros(qx.size, dtype=np.int8)
    failure[np.abs(qx - (crack_column * B + offset)) < 0.5 * dx + 1e-12] = 2
    if tensile_top:
        failure[qy > rows * H - dx * 0.5] = 1
    steps = np.linspace(0.0, 0.005, 6)
    return model.assign(
        mesh=((), np.int32(0), _attrs("mesh")),
        mesh_node_x=("mesh_node", gx.ravel(), _attrs("mesh_node_x")),
        mesh_node_y=("mesh_node", gy.ravel(), _attrs("mesh_node_y")),
        mesh_face_nodes=(("mesh_face", "mesh_face_node"), faces.astype(np.int32), _attrs("mesh_face_nodes")),
        qp_x=("qp", qx, _attrs("qp_x")),
        qp_y=("qp", qy, _attrs("qp_y")),
        qp_failure=("qp", failure, _attrs("qp_failure")),
        crack_indicator=("interface", head_line(model, crack_column).astype(float), _attrs("crack_indicator")),
        step_settlement=("step", steps, _attrs("step_settlement")),
        step_reaction=("step", 100.0 - 10.0 * np.sqrt(steps / 0.005), _attrs("step_reaction")),
    ).assign_attrs(_result_attrs(model, "jmm", {}))


@pytest.fixture
def build():
    """The builders and constants of this module (test modules cannot import a conftest)."""
    return SimpleNamespace(
        B=B, H=H, grid_model=grid_model, head_line=head_line,
        la_result=la_result, fdem_result=fdem_result, jmm_result=jmm_result,
    )


@pytest.fixture
def model():
    return grid_model()


@pytest.fixture
def results(model):
    """One result of each kind on the same model: {"la": ..., "fdem": ..., "jmm": ...}."""
    return {"la": la_result(model), "fdem": fdem_result(model), "jmm": jmm_result(model)}
