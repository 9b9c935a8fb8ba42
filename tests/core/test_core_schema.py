"""The machine-readable schemas stay in step with the human-readable contract (docs/format.md)."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

import masonryfw as mf
import masonryfw.format.schema
import masonryfw.plugin_api as mfp

ROOT = Path(__file__).resolve().parents[2]
FORMAT_MD = ROOT / "docs" / "format.md"


def _table_rows(section: str) -> list[list[str]]:
    """Rows of the first markdown table after the heading ``section`` in docs/format.md."""
    text = FORMAT_MD.read_text()
    start = text.index(section)
    rows = []
    for line in text[start:].splitlines()[1:]:
        if line.startswith("#"):
            break
        if line.startswith("|") and not set(line) <= set("|-: "):
            rows.append([c.strip() for c in line.strip("|").split("|")])
    return rows[1:]  # drop the header


def _names(cell: str) -> list[str]:
    """Backticked names in a table cell, without ellipses (`a`, `b`, ...)."""
    return [n for n in re.findall(r"`([^`]+)`", cell) if n != "..."]


@pytest.mark.parametrize(
    "section, kind",
    [("## Model variables", "model"), ("## Result variables", "result"), ("## Diagnosis variables", "diagnosis"),
     ("## 3D model variables", "model3d"), ("## 3D result variables", "result3d")],
)
def test_every_documented_variable_is_in_the_schema(section, kind):
    schema = mfp.load_schema(kind)
    documented = [n for row in _table_rows(section) for n in _names(row[0])]
    assert len(documented) > 5
    missing = [n for n in documented if n not in schema["variables"]]
    assert missing == []


@pytest.mark.parametrize(
    "section, kind",
    [("## Model variables", "model"), ("## Result variables", "result"), ("## Diagnosis variables", "diagnosis"),
     ("## 3D model variables", "model3d"), ("## 3D result variables", "result3d")],
)
def test_documented_dims_match_the_schema(section, kind):
    schema = mfp.load_schema(kind)
    for row in _table_rows(section):
        dims = [d.strip() for d in row[1].split(",")] if row[1] != "scalar" else []
        for name in _names(row[0]):
            if row[1].endswith("..."):
                continue  # the mesh row lists its dims loosely ("mesh_node, mesh_face, ...")
            assert schema["variables"][name]["dims"] == dims, name


def test_documented_flags_match_the_schema():
    text = FORMAT_MD.read_text()
    for name, meanings in [
        ("block_role", "unit lintel fixed_support moving_support voussoir"),
        ("interface_kind", "bed head support other"),
        ("interface_state", "intact open slide open_slide"),
        ("qp_failure", "elastic tensile shear tensile_shear"),
    ]:
        assert list(mfp.flags(name)) == meanings.split()
        assert list(mfp.flags(name).values()) == list(range(len(meanings.split())))
        assert name in text
    assert '`flag_meanings="unit lintel fixed_support moving_support voussoir"`' in text


def test_global_attributes_are_required_by_every_kind():
    for kind in masonryfw.format.schema.KINDS:
        attrs = mfp.load_schema(kind)["global_attributes"]
        assert attrs["Conventions"]["contains"] == "CF-1.11"
        assert attrs["masonryfw_format"]["value"] == kind
        assert attrs["masonryfw_format_version"]["value"] == mfp.FORMAT_VERSION
    result_attrs = mfp.load_schema("result")["global_attributes"]
    for name in ("plugin", "plugin_version", "solver", "solver_version", "core_version", "solver_options",
                 "wall_time_s"):
        assert result_attrs[name]["required"]


def test_unknown_kind_and_version_are_clear_errors():
    with pytest.raises(mf.ModelError, match="unknown dataset kind"):
        mfp.load_schema("mesh")
    with pytest.raises(mf.ModelError, match="unknown format version 7"):
        mfp.load_schema("model", 7)


@pytest.mark.parametrize("section, kind, base", [("## 3D model variables", "model3d", None),
                                                 ("## 3D result variables", "result3d", "model3d")])
def test_every_3d_variable_is_documented(section, kind, base):
    own = set(mfp.load_schema(kind)["variables"]) - (set(mfp.load_schema(base)["variables"]) if base else set())
    documented = {n for row in _table_rows(section) for n in _names(row[0])}
    assert own - {"dof"} == documented


def test_every_diagnosis_variable_is_documented():
    own = set(mfp.load_schema("diagnosis")["variables"]) - set(mfp.load_schema("model")["variables"])
    documented = {n for row in _table_rows("## Diagnosis variables") for n in _names(row[0])}
    assert own == documented
