"""Figures and words for a report, from the command line: sizes and resolutions, forces in kN, the widest crack
and its damage category marked, crack widths drawn, a big model plot without interface lines, the LTSM chart
with the tunnel's axis and a chart per part, alpha said in words, two R0 explained, a partial diagnosis said.

References: the PNG's pixels against --size x --dpi (matplotlib crops only empty margins), Test 12C's closed-form
R0 = 792 N x 0.6 / 1.1 = 432 N (datasets/README.md), the damage categories' crack-width bounds (Burland et al.
1977, docs/format.md), the profile's own axis."""
from __future__ import annotations

import struct

import numpy as np
import pytest
from support import cli

import masonryfw as mf
import masonryfw.plugin_api as mfp

R0_12C = 792.0 * 0.6 / 1.1


def png_size(path) -> tuple[int, int]:
    """Width and height in pixels, read from the PNG's IHDR chunk."""
    header = path.read_bytes()[:24]
    assert header[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", header[16:24])


@pytest.mark.parametrize("size, dpi, inches", [("6x4", 100, (6, 4)), ("180x120mm", 300, (180 / 25.4, 120 / 25.4)),
                                               ("16x10cm", 150, (16 / 2.54, 10 / 2.54))])
def test_every_plot_takes_a_size_and_a_resolution(tmp_path, test_12c_files, size, dpi, inches):
    done = cli(["plot", str(test_12c_files["fdem"]), "--kind", "mechanism", "-o", "m.png", "--size", size,
                "--dpi", str(dpi)], tmp_path)
    assert done.returncode == 0, done.stderr
    # a size asked for is the page's: exactly, the legend and titles laid out inside it
    width, height = png_size(tmp_path / "m.png")
    assert abs(width - inches[0] * dpi) <= 1 and abs(height - inches[1] * dpi) <= 1  # whole pixels


def test_the_default_resolution_is_fit_for_print_and_bad_sizes_are_refused(tmp_path, test_12c_files):
    done = cli(["plot", str(test_12c_files["la"]), "--kind", "cracks", "-o", "c.png"], tmp_path)
    assert done.returncode == 0 and "at 200 dpi" in done.stdout
    assert png_size(tmp_path / "c.png")[0] >= 1000  # was 472..700 px at 100 dpi
    for bad in ("7", "0x3", "axb", "7x5ft", "1e9x2"):
        refused = cli(["plot", str(test_12c_files["la"]), "--kind", "cracks", "-o", "c2.png", "--size", bad], tmp_path)
        assert refused.returncode == 2 and "--size" in refused.stderr and not (tmp_path / "c2.png").exists()


def test_the_la_headline_says_what_alpha_is_and_forces_are_in_kn_where_they_are_kn_sized(tmp_path):
    done = cli(["solve", "test-12c", "--plugin", "la", "-o", "r.nc"], tmp_path)
    alpha = float(mf.open_dataset(tmp_path / "r.nc").collapse_multiplier)
    assert f"in short: alpha = {alpha:.4f} (the share of R0 = {R0_12C:.4g} N the settling ground sheds before " \
           f"collapse), collapse reaction {(1 - alpha) * R0_12C:.4g} N" in done.stdout
    assert mfp.force_text(133_900.0) == "133.9 kN" and mfp.force_text(985.2) == "985.2 N"
    assert mfp.force_text(-2_500.0) == "-2.5 kN"


def test_the_mechanism_and_cracks_plots_mark_the_widest_crack_with_its_damage_category(test_12c_files):
    result = mf.open_dataset(test_12c_files["fdem"])
    k, width = int(result.step_crack_interface.values[-1]), float(result.step_crack_width_max.values[-1])
    # Burland et al. (1977): 0 up to 0.1 mm, 1 up to 1 mm, 2 up to 5 mm, 3 up to 15 mm, 4 up to 25 mm
    category = int(np.searchsorted([0.1e-3, 1e-3, 5e-3, 15e-3, 25e-3], width))
    names = {v: n.replace("_", " ") for n, v in mfp.flags("step_damage_category").items()}
    for kind in ("mechanism", "cracks"):
        ax = mf.render([result], kind).axes[0]
        labels = [t.get_text() for t in ax.get_legend().get_texts()]
        assert f"widest crack {width * 1000:.3g} mm:\ndamage category {category} {names[category]}" in labels
        rings = [line for line in ax.lines if line.get_marker() == "o"]
        assert len(rings) == 1
        if kind == "cracks":  # on the joint's midpoint, where the crack is
            assert np.allclose(rings[0].get_xydata()[0], [result.interface_x.values[k].mean(),
                                                          result.interface_y.values[k].mean()])
    la = mf.open_dataset(test_12c_files["la"])
    labels = [t.get_text() for t in mf.render([la], "mechanism").axes[0].get_legend().get_texts()]
    assert any(label.startswith("no crack widths: limit analysis") for label in labels)


def test_the_cracks_plot_draws_crack_widths_as_line_widths(test_12c_files):
    result = mf.open_dataset(test_12c_files["fdem"])
    from matplotlib.collections import LineCollection

    ax = mf.render([result], "cracks", {"widths": True}).axes[0]
    drawn = np.concatenate([c.get_linewidths() for c in ax.collections
                            if isinstance(c, LineCollection) and len(c.get_segments())])
    assert drawn.max() == pytest.approx(6.0) and drawn.min() >= 0.8  # the widest opening in the masonry: 6 pt
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    in_masonry = ~mfp.support_blocks(result.block_role.values)[result.interface_blocks.values].any(axis=1)
    state = mf.at_threshold(result).interface_state.values
    # a crack's width is the opening at its wider end (Burland et al. 1977 measure it where it is widest)
    widest = np.maximum(result.interface_opening.values, 0).max(axis=1)[(state > 0) & in_masonry].max()
    assert f"line width: the joint's opening at the last record,\nup to {widest * 1000:.3g} mm in the masonry" in legend


def test_the_model_plot_of_thousands_of_bricks_leaves_the_interfaces_out_unless_asked():
    from matplotlib.collections import LineCollection

    big = mf.build({"title": "big", "wall": {"width": 12.0, "height": 6.0, "thickness": 0.2},
                    "unit": {"length": 0.2, "height": 0.05}, "bond": {"pattern": "running"},
                    "material": {"unit_weight": 18000.0, "friction_angle": 30.0},
                    "supports": {"base": {"kind": "fixed", "start": 0.0, "end": 12.0}}, "loading": {"type": "tilt", "direction": 1}})
    assert big.sizes["block"] > 3000

    def lines(options):
        ax = mf.render([big], "model", options).axes[0]
        return [c for c in ax.collections if isinstance(c, LineCollection)]

    assert lines({}) == [] and lines({"interfaces": "no"}) == []
    assert sum(len(c.get_segments()) for c in lines({"interfaces": "yes"})) == big.sizes["interface"]
    small = mf.open_model("test-12c")
    ax = mf.render([small], "model").axes[0]
    assert sum(len(c.get_segments()) for c in ax.collections if isinstance(c, LineCollection)) == \
        small.sizes["interface"]


def test_the_ltsm_chart_shows_the_tunnel_axis_off_the_wall_and_each_part_on_its_own_zones():
    model = mf.open_model("gable-house")
    profile = mf.model_profile(model)
    assert profile.center > float(model.node_x.max())  # the tunnel's axis is beyond the wall's right end
    figure = mf.render([model], "ltsm")
    axes = [ax for ax in figure.axes if ax.axison]
    trough, charts = axes[0], axes[1:]
    low, high = trough.get_xlim()
    assert low < 0.0 and high > profile.center
    assert any(t.get_text() == f"tunnel axis, x = {profile.center:.3g} m" for t in trough.texts)
    stages = mfp.assess(model, float(model.settlement_target))
    assert len(charts) == len(stages.parts) >= 2
    for chart, part in zip(charts, stages.parts):
        assert chart.get_title().startswith(f"{'sagging' if part.sagging else 'hogging'} {part.start:.3g}..")
        assert chart.get_legend() is None or chart is charts[-1]
    legend = charts[-1].get_legend()
    # the zones' legend stands beside the last chart, off every zone
    assert legend.get_bbox_to_anchor().x0 >= charts[-1].get_window_extent().x1


def test_a_figure_and_a_report_of_an_interrupted_diagnosis_say_it_is_partial(tmp_path):
    from masonryfw_compare.report import _diagnosis_section

    done = cli(["diagnose", "facade-1", "--cracks", str(_survey("facade-1-cracks.geojson")), "--profiles", "step",
                "--rerank", "0", "-o", "d.nc"], tmp_path)
    assert done.returncode == 0, done.stderr
    whole = mf.open_dataset(tmp_path / "d.nc")
    assert "PARTIAL" not in mf.render([whole], "diagnosis")._suptitle.get_text()
    cut = whole.assign_attrs(interrupted=1, scenarios_planned=whole.sizes["candidate"] + 40)
    title = mf.render([cut], "diagnosis")._suptitle.get_text()
    assert title.startswith(f"PARTIAL: the search was interrupted after {whole.sizes['candidate']} of "
                            f"{whole.sizes['candidate'] + 40} scenarios")
    mf.save(cut, tmp_path / "cut.nc")
    assert "Partial: the search was interrupted" in "".join(_diagnosis_section(str(tmp_path / "cut.nc"), cut))


def _survey(name: str):
    from pathlib import Path

    return Path(__file__).resolve().parents[3] / "datasets" / "surveys" / name


def test_two_r0_of_one_model_are_explained_in_the_report_and_the_comparison(tmp_path, test_12c_files):
    la, fdem = (mf.open_dataset(test_12c_files[s]) for s in ("la", "fdem"))
    r0 = {n.name: n.value for n in mf.key_numbers(fdem)}["dead_reaction"]
    assert {n.name: n.value for n in mf.key_numbers(la)}["dead_reaction"] == pytest.approx(R0_12C, rel=1e-12)
    text = mfp.r0_text([la, fdem], ["A", "B"])
    if abs(r0 - R0_12C) <= mfp.R0_SPREAD * R0_12C:  # they agree: nothing to explain
        assert text == ""
    # two R0 that differ (a wall over partly settling ground: fdem's split at rest is not la's convention)
    shifted = fdem.assign(step_reaction=fdem.step_reaction * 1.04)
    text = mfp.r0_text([la, shifted], ["A", "B"])
    assert text.startswith(f"R0 is not one number here: A reports {mfp.force_text(R0_12C)}, W L_s / L_total")
    assert f"B reports {mfp.force_text(1.04 * r0)}, the reaction it computes at rest" in text
    assert "statically indeterminate" in text
    mf.save(shifted, tmp_path / "b.nc")
    done = cli(["report", str(test_12c_files["la"]), "b.nc", "-o", "r.html"], tmp_path)
    assert done.returncode == 0, done.stderr
    assert 'id="r0-note"' in (tmp_path / "r.html").read_text()
    compared = cli(["compare", str(test_12c_files["la"]), "b.nc"], tmp_path)
    assert "R0 is not one number here" in compared.stdout


@pytest.mark.parametrize("size", [(180 / 25.4, 120 / 25.4), (4.0, 3.0)])
def test_what_a_figure_shows_fits_the_page_asked_for(test_12c_files, size):
    """Titles and legends beside the axes stay on the page: their text is scaled down to fit a small one."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    la, fdem, jmm = (mf.open_dataset(test_12c_files[s]) for s in ("la", "fdem", "jmm"))
    cases = [([fdem], "mechanism", {}), ([fdem], "cracks", {"widths": True}), ([la], "mechanism", {}),
             ([la], "forces", {}), ([jmm], "plastic", {}), ([la, fdem, jmm], "history", {}),
             ([la, fdem], "compare", {}), ([mf.open_model("test-12c")], "model", {"numbers": True}),
             ([mf.open_model("gable-house")], "ltsm", {})]
    for datasets, kind, options in cases:
        figure = mf.render(datasets, kind, options, size=size)
        canvas = FigureCanvasAgg(figure)
        canvas.draw()
        box = figure.get_tightbbox(canvas.get_renderer())
        assert tuple(figure.get_size_inches()) == pytest.approx(size)
        assert box.x0 >= -0.011 and box.y0 >= -0.011, kind
        assert box.x1 <= size[0] + 0.011 and box.y1 <= size[1] + 0.011, kind


def test_the_history_axis_is_in_kn_where_the_forces_are_kn_sized(test_12c_files):
    fdem = mf.open_dataset(test_12c_files["fdem"])
    ax = mf.render([fdem], "history").axes[0]
    assert ax.get_ylabel().endswith("[N]")  # Test 12C: R0 = 432 N
    heavy = fdem.assign(step_reaction=fdem.step_reaction * 300.0)  # the same history, 300 times heavier
    heavy["dead_load"] = fdem.dead_load * 300.0
    ax = mf.render([heavy], "history").axes[0]
    assert ax.get_ylabel().endswith("[kN]")
    ax.figure.canvas.draw()
    ticks = {t.get_position()[1]: t.get_text() for t in ax.get_yticklabels()}
    assert all(text == f"{value / 1000:g}" for value, text in ticks.items())  # the curves keep newtons
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert f"dead reaction R0 = {mfp.force_text(300 * R0_12C)}" in legend
