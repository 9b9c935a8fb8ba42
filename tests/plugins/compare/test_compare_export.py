"""VTK export: the files open with meshio.read and carry the arrays with the right sizes and values."""
from __future__ import annotations

import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest
from click.testing import CliRunner

import masonryfw as mf
from masonryfw_compare import export_vtk
from masonryfw_compare.commands import export_command


def _cell_array(mesh, name: str) -> np.ndarray:
    return np.concatenate([np.asarray(a) for a in mesh.cell_data[name]])


def test_blocks_and_joints_of_a_limit_analysis_result(results, tmp_path):
    la = results["la"]
    written = export_vtk(la, tmp_path / "wall.vtu")
    assert [p.name for p in written] == ["wall.vtu", "wall_joints.vtu", "wall.vtm"]

    blocks = meshio.read(tmp_path / "wall.vtu")
    assert blocks.points.shape == (104, 3)  # 26 blocks x 4 own vertices
    assert sum(len(c.data) for c in blocks.cells) == 26 and blocks.cells[0].type == "quad"
    order = _cell_array(blocks, "block_index")
    assert sorted(order) == list(range(26))
    assert np.array_equal(_cell_array(blocks, "macro_block"), la.macro_block.values[order])
    assert np.array_equal(_cell_array(blocks, "block_role"), la.block_role.values[order])
    assert _cell_array(blocks, "centroid_displacement").shape == (26, 3)
    # translation mechanism: every vertex of a moving block goes down by exactly 1
    moving = np.repeat(la.block_displacement.values[:, 1] < 0, 4)
    displacement = blocks.point_data["displacement"]
    assert np.allclose(displacement[moving], [0, -1, 0]) and np.allclose(displacement[~moving], 0)

    joints = meshio.read(tmp_path / "wall_joints.vtu")
    assert joints.points.shape == (88, 3) and joints.cells[0].type == "line" and len(joints.cells[0].data) == 44
    assert np.array_equal(_cell_array(joints, "crack_indicator"), la.crack_indicator.values)
    assert np.array_equal(_cell_array(joints, "interface_state"), la.interface_state.values)
    assert np.allclose(joints.points[:, 0], la.interface_x.values.ravel())
    for name in ("interface_opening", "interface_slip", "interface_normal_force", "interface_shear_force"):
        assert np.allclose(joints.point_data[name], la[name].values.ravel()), name

    index = ET.parse(tmp_path / "wall.vtm").getroot()
    assert [d.get("file") for d in index.iter("DataSet")] == ["wall.vtu", "wall_joints.vtu"]


def test_continuum_mesh_and_plastic_points(results, tmp_path):
    jmm = results["jmm"]
    written = export_vtk(jmm, tmp_path / "c.vtu")
    assert [p.name for p in written] == ["c.vtu", "c_joints.vtu", "c_mesh.vtu", "c_qp.vtu", "c.vtm"]
    mesh = meshio.read(tmp_path / "c_mesh.vtu")
    assert mesh.points.shape == (jmm.sizes["mesh_node"], 3)
    assert mesh.cells[0].type == "quad" and np.array_equal(mesh.cells[0].data, jmm.mesh_face_nodes.values)
    points = meshio.read(tmp_path / "c_qp.vtu")
    assert points.points.shape == (jmm.sizes["qp"], 3)
    assert np.array_equal(points.point_data["qp_failure"], jmm.qp_failure.values)
    assert np.bincount(points.point_data["qp_failure"]).tolist() == [70, 12, 14]  # 96 faces; top row, crack line
    blocks = meshio.read(tmp_path / "c.vtu")
    assert "displacement" not in blocks.point_data  # a continuum result has no block motion


def test_mixed_polygons_are_grouped_by_vertex_count(results, tmp_path):
    """A pentagon among quads: its own cell block, mapped back through block_index."""
    la = results["la"]
    x, y = la.node_x.values.copy(), la.node_y.values.copy()
    # split the top edge of block 23 (last unit, top right) with a vertex at its midpoint
    start = 23 * 4
    x = np.insert(x, start + 3, 0.5 * (x[start + 2] + x[start + 3]))
    y = np.insert(y, start + 3, y[start + 2])
    counts = la.block_node_count.values.copy()
    counts[23] = 5
    pentagon = la.drop_dims("node").assign(
        node_x=("node", x, la.node_x.attrs), node_y=("node", y, la.node_y.attrs),
        block_node_count=("block", counts, la.block_node_count.attrs),
    )
    export_vtk(pentagon, tmp_path / "p.vtu")
    blocks = meshio.read(tmp_path / "p.vtu")
    assert sorted((c.type, len(c.data)) for c in blocks.cells) == [("polygon", 1), ("quad", 25)]
    assert blocks.cell_data["block_index"][[c.type for c in blocks.cells].index("polygon")].tolist() == [23]


def test_the_export_command_writes_the_files(results, tmp_path):
    source = tmp_path / "r.nc"
    mf.save(results["fdem"], source)
    missing = CliRunner().invoke(export_command, [str(source), "-o", str(tmp_path / "out" / "f.vtu")])
    assert missing.exit_code == 1 and "directory" in str(missing.exception) and not (tmp_path / "out").exists()
    (tmp_path / "out").mkdir()
    outcome = CliRunner().invoke(export_command, [str(source), "--format", "vtk", "-o", str(tmp_path / "out" / "f.vtu")])
    assert outcome.exit_code == 0, outcome.output
    assert "f_joints.vtu" in outcome.output
    assert meshio.read(tmp_path / "out" / "f.vtu").points.shape == (104, 3)
    with pytest.raises(mf.MasonryError, match="must end in .vtu"):
        export_vtk(results["fdem"], tmp_path / "f.vtk")


def test_a_planar_run_with_snapshots_exports_them_as_a_time_series(tmp_path):
    """fdem on Test 8C with two snapshots: each written as the blocks at that snapshot (a vertex of a block moves
    by the snapshot's rigid motion of that block, finite rotation), listed in a .pvd at its settlement."""
    result = mf.solve(mf.open_model("test-8c"), "fdem", {"snapshots": "0.001,0.002"})
    written = export_vtk(result, tmp_path / "wall.vtu")
    assert [p.name for p in written][-4:] == ["wall_series_000.vtu", "wall_series_001.vtu", "wall_series.pvd",
                                              "wall.vtm"]
    times = [float(d.get("timestep")) for d in ET.parse(tmp_path / "wall_series.pvd").getroot().iter("DataSet")]
    assert times == result.snapshot_settlement.values.tolist()
    second = meshio.read(tmp_path / "wall_series_001.vtu")
    order = _cell_array(second, "block_index")
    block = int(order[0])  # the first cell's block and its first vertex
    vertex = second.cells[0].data[0][0]
    c = np.array([result.block_centroid_x.values[block], result.block_centroid_y.values[block]])
    u = result.snapshot_block_displacement.values[1, block]
    turn = result.snapshot_block_rotation.values[1, block]
    rotation = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
    expected = u + (rotation - np.eye(2)) @ (second.points[vertex, :2] - c)
    np.testing.assert_allclose(second.point_data["displacement"][vertex, :2], expected, atol=1e-12)
