"""``masonryfw.results.summary``: the rows and texts ``compare`` prints and reports show."""
from __future__ import annotations

import csv
import io

import numpy as np

import masonryfw.plugin_api as mfp
import masonryfw.testing as mt


def test_csv_keeps_every_digit_and_leaves_missing_values_empty():
    text = mfp.csv_text(["a", "b", "c"], [[np.float64(0.1) + np.float64(0.2), None, 3], ["x", 1e-300, np.int64(2)]])
    rows = list(csv.reader(io.StringIO(text)))
    assert rows == [["a", "b", "c"], ["0.30000000000000004", "", "3"], ["x", "1e-300", "2"]]
    assert float(rows[1][0]) == 0.1 + 0.2


def test_text_table_aligns_the_columns_and_puts_the_note_last():
    rows = [mfp.Row("alpha", ("0.7517", "-"), "collapse multiplier", (0.7517, None)),
            mfp.Row("collapse reaction", ("107.3 N", "-"), "at collapse", (107.3, None))]
    lines = mfp.text_table(["", "A", "B"], rows).splitlines()
    assert lines[1] == "alpha              0.7517   -  collapse multiplier"
    assert lines[2] == "collapse reaction  107.3 N  -  at collapse"
    assert lines[0].index("A") == lines[1].index("0.7517")


def test_headline_rows_leave_a_dash_where_a_result_has_no_such_number():
    limit = mt.rectangles_model([(0.0, -0.2, 0.5, 0.0), (0.5, -0.2, 1.0, 0.0), (0.0, 0.0, 1.0, 0.5)],
                                ["fixed_support", "moving_support", "unit"]).assign(collapse_multiplier=((), 0.25))
    history = limit.drop_vars("collapse_multiplier").assign(
        step_settlement=("step", [0.0, 0.001, 0.002]), step_reaction=("step", [150.0, 100.0, 100.0]))
    rows = {r.label: r for r in mfp.headline_rows([limit, history])}
    r0 = 12e3 * 0.5 * 0.1 * 0.5  # the moving support's half of the weight
    assert rows["alpha"].cells == ("0.2500", "-") and rows["alpha"].values == (0.25, None)
    assert rows["dead reaction R0"].values == (r0, 150.0)
    assert rows["minimum reaction"].cells == ("-", "100 N at 1 mm")
