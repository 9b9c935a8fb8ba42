"""Shared fixtures of the core tests: a five-block model written by hand with plain xarray.

The wall (m), thickness 0.1, unit weight 12 kN/m3::

    y 0.3 +-----------------------------+
          |           block 2            |   1.0 x 0.1 -> 120 N
    y 0.2 +----------+------------------+
          | block 0  |     block 1       |   0.4 x 0.2 -> 96 N, 0.6 x 0.2 -> 144 N
    y 0   +----------+------------------+
          | 3 fixed  |   4 moving        |   supports, weightless
    y-0.1 +----------+------------------+
          x 0       0.4                1.0

Masonry weight W = 360 N. Settlement convention: the moving support (contact
0.6 of 1.0 m) carries dead +216 N (up) and live -216 N (down).
"""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import masonryfw.plugin_api as mfp

RECTANGLES = [  # xmin, xmax, ymin, ymax, role
    (0.0, 0.4, 0.0, 0.2, "unit"),
    (0.4, 1.0, 0.0, 0.2, "unit"),
    (0.0, 1.0, 0.2, 0.3, "unit"),
    (0.0, 0.4, -0.1, 0.0, "fixed_support"),
    (0.4, 1.0, -0.1, 0.0, "moving_support"),
]
INTERFACES = [  # side 0, side 1, (x0, x1), (y0, y1), kind
    (0, 1, (0.4, 0.4), (0.0, 0.2), "head"),
    (0, 2, (0.0, 0.4), (0.2, 0.2), "bed"),
    (1, 2, (0.4, 1.0), (0.2, 0.2), "bed"),
    (3, 0, (0.0, 0.4), (0.0, 0.0), "support"),
    (4, 1, (0.4, 1.0), (0.0, 0.0), "support"),
    (3, 4, (0.4, 0.4), (-0.1, 0.0), "support"),
]
THICKNESS, UNIT_WEIGHT = 0.1, 12_000.0
MOVING_SUPPORT_LOAD = 216.0  # W * 0.6 / 1.0


def _var(name, dims, values):
    return (dims, np.asarray(values), mfp.variable_attrs(name))


def hand_model() -> xr.Dataset:
    """The model drawn in the module docstring, docs/format.md-complete, built without the builder."""
    roles, kinds = mfp.flags("block_role"), mfp.flags("interface_kind")
    rects = np.array([r[:4] for r in RECTANGLES])
    node_x = np.stack([rects[:, 0], rects[:, 1], rects[:, 1], rects[:, 0]], axis=1).ravel()
    node_y = np.stack([rects[:, 2], rects[:, 2], rects[:, 3], rects[:, 3]], axis=1).ravel()
    role = np.array([roles[r[4]] for r in RECTANGLES], dtype=np.int8)
    area = (rects[:, 1] - rects[:, 0]) * (rects[:, 3] - rects[:, 2])
    unit_weight = np.where(role <= roles["lintel"], UNIT_WEIGHT, 0.0)
    dead = np.zeros((5, 3))
    dead[:, 1] = -area * THICKNESS * unit_weight
    dead[4, 1] = MOVING_SUPPORT_LOAD
    live = np.zeros((5, 3))
    live[4, 1] = -MOVING_SUPPORT_LOAD
    fixed = np.zeros((5, 3), dtype=np.int8)
    fixed[3] = (1, 1, 1)
    fixed[4] = (1, 0, 1)
    direction = np.zeros((5, 3))
    direction[4, 1] = -1.0
    n_if = len(INTERFACES)
    ds = xr.Dataset(
        {
            "node_x": _var("node_x", "node", node_x),
            "node_y": _var("node_y", "node", node_y),
            "block_node_count": _var("block_node_count", "block", np.full(5, 4, dtype=np.int32)),
            "block_role": _var("block_role", "block", role),
            "block_thickness": _var("block_thickness", "block", np.full(5, THICKNESS)),
            "block_unit_weight": _var("block_unit_weight", "block", unit_weight),
            "interface_blocks": _var("interface_blocks", ("interface", "side"), [i[:2] for i in INTERFACES]),
            "interface_x": _var("interface_x", ("interface", "end"), [i[2] for i in INTERFACES]),
            "interface_y": _var("interface_y", ("interface", "end"), [i[3] for i in INTERFACES]),
            "interface_kind": _var("interface_kind", "interface", np.array([kinds[i[4]] for i in INTERFACES], dtype=np.int8)),
            "interface_friction": _var("interface_friction", "interface", np.full(n_if, 0.4)),
            "interface_cohesion": _var("interface_cohesion", "interface", np.zeros(n_if)),
            "interface_tensile_strength": _var("interface_tensile_strength", "interface", np.zeros(n_if)),
            "dead_load": _var("dead_load", ("block", "axis"), dead[:, :2]),
            "dead_moment": _var("dead_moment", "block", dead[:, 2]),
            "live_load": _var("live_load", ("block", "axis"), live[:, :2]),
            "live_moment": _var("live_moment", "block", live[:, 2]),
            "block_fixed": _var("block_fixed", ("block", "dof"), fixed),
            "settlement_direction": _var("settlement_direction", ("block", "dof"), direction),
            "block_geometry": ((), np.int32(0), mfp.variable_attrs("block_geometry")),
        },
        coords={"dof": ("dof", ["ux", "uy", "rz"], mfp.variable_attrs("dof"))},
        attrs={
            "Conventions": "CF-1.11",
            "masonryfw_format": "model",
            "masonryfw_format_version": 2,
            "title": "Hand wall",
        },
    )
    return ds


@pytest.fixture(scope="session")
def make_model():
    """The function that builds the hand model (for module-scoped fixtures)."""
    return hand_model


@pytest.fixture
def model() -> xr.Dataset:
    """A fresh in-memory copy of the hand-built model."""
    return hand_model()


@pytest.fixture
def model_file(tmp_path):
    """The hand-built model written with plain ``xarray.Dataset.to_netcdf``."""
    path = tmp_path / "hand_wall.nc"
    hand_model().to_netcdf(path)
    return path


class _SolverPlugin:
    def __init__(self, solver):
        self.solver = solver

    @mfp.hookimpl
    def masonryfw_solvers(self):
        return [self.solver]


@pytest.fixture
def registered():
    """``register(solve, name, **record)``: a hand-made solver registered as a plugin for one test."""
    from masonryfw.contract import registry

    registry.reset()
    manager = mfp.plugin_manager()

    def register(solve, name="tipping", **record):
        manager.register(_SolverPlugin(mfp.Solver(name, "hand mechanism", solve, **record)), name=name)
    yield register
    registry.reset()




@pytest.fixture
def command():
    """``command(args, cwd, env=None, python=())``: a :class:`support.Command` started; killed if the test leaves
    it running."""
    from support import Command

    started = []

    def start(args, cwd, env=None, python=()):
        started.append(Command(args, cwd, env, python))
        return started[-1]
    yield start
    for each in started:
        each.stop()
