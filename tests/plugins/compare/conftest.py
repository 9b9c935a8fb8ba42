"""Models and hand-made results for the compare plugin's tests.

The model is a stack-bonded grid wall (``rows`` x ``cols`` units of b x h) on two
support blocks, from the kit (:func:`masonryfw.testing.rectangles_model`): a
fixed one under the first ``split`` columns and a moving one under the rest.
Results are written by hand after docs/format.md ("Result variables") for three
kinds of solver, limit analysis (LA), FEM/DEM and a continuum (JMM), so that
every score below can be computed by hand.
"""
from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp
import masonryfw.testing as mt

B, H = 0.2, 0.1  # unit length and height [m]
WEIGHT = 12e3  # N m-3
THICKNESS = 0.1


#: What the core writes on crack_indicator, with the threshold the fixtures' hand-made indicators stand for.
INDICATOR_ATTRS = {**mfp.variable_attrs("crack_indicator"), "crack_threshold": mf.CRACK_THRESHOLD}


def _attrs(name: str) -> dict:
    return mfp.variable_attrs(name)


def grid_model(rows: int = 4, cols: int = 6, split: int = 3, title: str = "Grid wall") -> xr.Dataset:
    """A checked model: units ``r * cols + c``, then the fixed and the moving support."""
    r, c = np.divmod(np.arange(rows * cols), cols)
    units = np.column_stack([c * B, r * H, (c + 1) * B, (r + 1) * H])
    supports = [(0.0, -H, split * B, 0.0), (split * B, -H, cols * B, 0.0)]
    roles = ["unit"] * (rows * cols) + ["fixed_support", "moving_support"]
    return mt.rectangles_model(np.vstack([units, supports]), roles, unit_weight=WEIGHT, thickness=THICKNESS,
                               title=title)


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


def _result_attrs(model: xr.Dataset, solver: str, options: dict, **extra) -> dict:
    return {
        **model.attrs,
        "masonryfw_format": "result",
        "plugin": solver,
        "plugin_version": "0",
        "solver": solver,
        "solver_version": "0+000000000000",
        "core_version": "0+000000000000",
        "solver_options": json.dumps(options),
        "wall_time_s": 0.01,
        **extra,
    }


def _translation_mechanism(model: xr.Dataset, first_moving_column: int) -> np.ndarray:
    """Units of columns >= first_moving_column and the moving support go down by 1."""
    column = unit_column(model)
    u = np.zeros((model.sizes["block"], 3))
    u[column >= first_moving_column, 1] = -1.0
    u[model.block_role.values == 3, 1] = -1.0
    return u


def la_result(model: xr.Dataset, first_moving_column: int = 3, cracked=None, backend: str = "highs") -> xr.Dataset:
    """A limit-analysis result: the units right of a vertical crack translate down with the support.

    ``cracked`` (interface mask) defaults to every joint whose blocks move apart.
    """
    u = _translation_mechanism(model, first_moving_column)
    opening, slip = mfp.relative_motion(model, u, "small")
    moving_apart = (np.abs(opening).max(axis=1) > 0) | (np.abs(slip).max(axis=1) > 0)
    cracked = moving_apart if cracked is None else np.asarray(cracked, dtype=bool)
    state = np.where(opening.max(axis=1) > 0, 1, 0) + np.where(np.abs(slip).max(axis=1) > 0, 2, 0)
    normal = np.where(np.arange(model.sizes["interface"])[:, None] % 3 == 0, [[1.0, 3.0]], [[2.0, 2.0]]) * 10.0
    macro = np.where(u[:, 1] < 0, 1, 0)
    return model.assign(
        collapse_multiplier=((), 0.3, _attrs("collapse_multiplier")),
        **mfp.motion_variables(u),
        interface_opening=(("interface", "end"), opening, _attrs("interface_opening")),
        interface_slip=(("interface", "end"), slip, _attrs("interface_slip")),
        interface_normal_force=(("interface", "end"), normal, _attrs("interface_normal_force")),
        interface_shear_force=(("interface", "end"), 0.2 * normal, _attrs("interface_shear_force")),
        interface_state=("interface", np.where(cracked, state, 0).astype(np.int8), _attrs("interface_state")),
        crack_indicator=("interface", cracked.astype(float), INDICATOR_ATTRS),
        macro_block=("block", macro.astype(np.int32), _attrs("macro_block")),
    ).assign_attrs(_result_attrs(model, "la", {"solver": backend}, rotations="small", flow_rule="associative"))


def fdem_result(model: xr.Dataset, first_moving_column: int = 3) -> xr.Dataset:
    """An incremental discrete result: 5 mm final settlement, reaction history, no forces or states.

    The crack indicator is chosen by hand (the head joints of one line), independent of the motion."""
    u = 0.005 * _translation_mechanism(model, first_moving_column)
    steps = np.linspace(0.0, 0.005, 11)
    crack = head_line(model, first_moving_column).astype(float)
    opening, slip = mfp.relative_motion(model, u, "finite")
    return model.assign(
        **mfp.motion_variables(u),
        interface_opening=(("interface", "end"), opening, _attrs("interface_opening")),
        interface_slip=(("interface", "end"), slip, _attrs("interface_slip")),
        crack_indicator=("interface", crack, INDICATOR_ATTRS),
        macro_block=("block", np.where(u[:, 1] < 0, 1, 0).astype(np.int32), _attrs("macro_block")),
        step_settlement=("step", steps, _attrs("step_settlement")),
        step_reaction=("step", 100.0 * np.exp(-steps / 0.001), _attrs("step_reaction")),
    ).assign_attrs(_result_attrs(model, "fdem", {}, rotations="finite", flow_rule="nonassociative"))


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
        mesh_node_x=("mesh_node", gx.ravel(), _attrs("mesh_node_x")),
        mesh_node_y=("mesh_node", gy.ravel(), _attrs("mesh_node_y")),
        mesh_face_nodes=(("mesh_face", "mesh_face_node"), faces.astype(np.int32), _attrs("mesh_face_nodes")),
        qp_x=("qp", qx, _attrs("qp_x")),
        qp_y=("qp", qy, _attrs("qp_y")),
        qp_failure=("qp", failure, _attrs("qp_failure")),
        crack_indicator=("interface", head_line(model, crack_column).astype(float), INDICATOR_ATTRS),
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


@pytest.fixture(scope="session")
def test_12c_files(tmp_path_factory):
    """Test 12C solved by la, fdem and jmm with their defaults, as result files: ``{solver: path}``."""
    folder = tmp_path_factory.mktemp("test-12c")
    model = mf.open_model("test-12c")
    files = {}
    for solver in ("la", "fdem", "jmm"):
        files[solver] = folder / f"test-12c.{solver}.nc"
        mf.save(mf.solve(model, solver), files[solver])
    return files
