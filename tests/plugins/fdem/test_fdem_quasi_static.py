"""A reaction history is quasi-static, or says it is not: fdem reports the median unbalanced force ratio and the
kinetic-over-stored energy of its settlement records, and a history above ``QUASI_STATIC_RATIO`` is called dynamic
(by the solve, the key numbers and the figures' headline).

References: la's collapse reaction (1 - alpha) R0 of the same wall (a second formulation: rigid-block limit
analysis), which a quasi-static fdem minimum approaches from below and a dynamic one misses; the loading rate
halved, which a quasi-static history does not feel."""
from __future__ import annotations

import pytest
from support import cli

import masonryfw as mf
import masonryfw.plugin_api as mfp


@pytest.fixture(scope="module")
def collapse_reaction() -> float:
    numbers = {n.name: n.value for n in mf.key_numbers(mf.solve(mf.open_model("test-12c"), "la"))}
    return numbers["collapse_reaction"]


def _numbers(result) -> dict:
    return {n.name: n.value for n in mf.key_numbers(result)}


@pytest.mark.parametrize("rate", [2e-3, 1e-3])
def test_a_quasi_static_history_says_so_and_its_minimum_does_not_feel_the_loading_rate(rate, collapse_reaction):
    numbers = _numbers(mf.solve(mf.open_model("test-12c"), "fdem", {"loading_rate": rate}))
    assert numbers["unbalanced_ratio"] < 0.1 * mfp.QUASI_STATIC_RATIO
    assert numbers["kinetic_energy_ratio"] < 0.05
    # the minimum is la's collapse reaction within 5 % (fdem's joints do not dilate: a little below)
    assert numbers["minimum_reaction"] == pytest.approx(collapse_reaction, rel=0.05)
    assert mfp.quasi_static_text(numbers).startswith("quasi-static (unbalanced ")


def test_a_history_loaded_too_fast_is_called_dynamic_where_its_numbers_are_read(tmp_path, collapse_reaction):
    done = cli(["solve", "test-12c", "--plugin", "fdem", "--option", "loading_rate=0.05", "-o", "r.nc"], tmp_path)
    assert done.returncode == 0, done.stderr
    assert "the reaction history is dynamic, not quasi-static" in done.stderr
    result = mf.open_dataset(tmp_path / "r.nc")
    numbers = _numbers(result)
    assert numbers["unbalanced_ratio"] > mfp.QUASI_STATIC_RATIO
    # and the minimum it reports is far from the collapse reaction the quasi-static run finds
    assert abs(numbers["minimum_reaction"] - collapse_reaction) > 0.3 * collapse_reaction
    assert "(DYNAMIC: unbalanced force ratio" in mf.headline_text(result)
    assert "in short: " in done.stdout and "DYNAMIC" in done.stdout
    rows = {row.label: row.cells[0] for row in mfp.headline_rows([result])}
    assert rows["quasi-static check"].startswith("DYNAMIC (unbalanced ")
