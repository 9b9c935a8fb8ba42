"""``masonryfw report``: one self-contained HTML file, rendered in a real headless browser (Chromium),
whose numbers are the result files' own.

Chromium comes from the distribution's packages (``.ci/install-browser``); the test fails, with that
hint, where it is missing.
"""
from __future__ import annotations

import shutil
import subprocess
from html.parser import HTMLParser

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

import masonryfw as mf
from masonryfw.cli import cli
from masonryfw_compare.history_plot import gravity_records

R0 = 792.0 * 0.6 / 1.1  # Test 12C's dead load on its settling support (datasets/README.md)
#: Appended to a copy of the report: after loading, the body says how many images decoded, and how big.
HARNESS = """<script>window.addEventListener("load", () => {
  const images = [...document.images];
  document.body.dataset.decoded = images.filter(i => i.complete && i.naturalWidth > 0).length;
  document.body.dataset.images = images.length;
  document.body.dataset.narrowest = Math.min(...images.map(i => i.naturalWidth));
});</script>"""


class Cells(HTMLParser):
    """Every element's attributes, by tag."""

    def __init__(self):
        super().__init__()
        self.tags: list[tuple[str, dict]] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))


def parsed(text: str) -> Cells:
    cells = Cells()
    cells.feed(text)
    return cells


def browser() -> str:
    found = shutil.which("chromium") or shutil.which("chromium-browser")
    if found is None:
        pytest.fail("no Chromium: run .ci/install-browser (Debian/Ubuntu: apt-get install chromium)")
    return found


def chromium(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([browser(), "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                           "--hide-scrollbars", *args], capture_output=True, text=True, timeout=120)


@pytest.fixture(scope="module")
def report(test_12c_files, tmp_path_factory):
    out = tmp_path_factory.mktemp("report") / "test-12c.html"
    paths = [test_12c_files[s] for s in ("la", "fdem", "jmm")]
    run = CliRunner().invoke(cli, ["report", *map(str, paths), "-o", str(out), "--no-progress"])
    assert run.exit_code == 0, run.output
    return out


def test_the_report_is_one_self_contained_file(report):
    text = report.read_text()
    tags = parsed(text).tags
    sources = [a["src"] for t, a in tags if t == "img"]
    assert len(sources) >= 10 and all(s.startswith("data:image/png;base64,") for s in sources)
    assert not [t for t, _ in tags if t in ("script", "link", "iframe")]
    assert "http://" not in text and "https://" not in text
    assert 'title = "Test 12C"' in text  # the source spec
    for kind in ("model", "history", "mechanism", "cracks", "forces", "plastic", "compare"):
        assert f'data-kind="{kind}"' in text, kind


def test_the_report_s_numbers_are_the_result_files(report, test_12c_files):
    cells = {(a["data-row"], a["data-column"]): float(a["data-value"])
             for t, a in parsed(report.read_text()).tags if t == "td" and "data-value" in a}
    la, fdem, jmm = (mf.open_dataset(test_12c_files[s]) for s in ("la", "fdem", "jmm"))
    alpha = float(la.collapse_multiplier.values)
    assert cells[("alpha", "A")] == alpha
    assert cells[("collapse reaction", "A")] == float(la.moving_support_reaction.values)
    assert cells[("collapse reaction", "A")] == pytest.approx((1 - alpha) * R0, rel=1e-6)
    assert cells[("dead reaction R0", "A")] == pytest.approx(R0, rel=1e-12)
    for column, ds in (("B", fdem), ("C", jmm)):
        s, r = ds.step_settlement.values, ds.step_reaction.values
        dead = gravity_records(s) - 1
        assert cells[("dead reaction R0", column)] == r[dead]
        assert cells[("minimum reaction", column)] == r[dead:].min()
        assert cells[("final settlement", column)] == s[-1]
        assert cells[("widest crack", column)] == ds.step_crack_width_max.values[-1]
        assert cells[("damage category", column)] == ds.step_damage_category.values[-1]
    for column, (a, b) in (("A-B", (la, fdem)), ("A-C", (la, jmm)), ("B-C", (fdem, jmm))):
        scores = mf.compare(a, b, "crack")
        for name in ("crack_f1", "macro_block_ari", "mechanism_cosine", "locus_distance"):
            assert cells[(name, column)] == float(scores[name]), (name, column)


def test_the_report_renders_in_headless_chromium(report, tmp_path):
    page = tmp_path / "page.html"
    page.write_text(report.read_text().replace("</body>", HARNESS + "</body>"))
    dumped = chromium("--virtual-time-budget=10000", "--dump-dom", page.as_uri())
    assert dumped.returncode == 0, dumped.stderr[-2000:]
    body = next(a for t, a in parsed(dumped.stdout).tags if t == "body")
    assert int(body["data-images"]) >= 10
    assert body["data-decoded"] == body["data-images"]  # every embedded figure decoded
    assert int(body["data-narrowest"]) > 300
    shot = tmp_path / "shot.png"
    taken = chromium("--window-size=1100,2400", f"--screenshot={shot}", report.as_uri())
    assert taken.returncode == 0, taken.stderr[-2000:]
    with Image.open(shot) as image:
        grey = np.asarray(image.convert("L"))
    assert grey.shape == (2400, 1100)
    assert (grey < 200).mean() > 0.02  # text, tables and figures drawn, not a blank page


def test_a_report_refuses_models_and_results_of_different_walls(test_12c_files, tmp_path):
    other = tmp_path / "test-8c.la.nc"
    mf.save(mf.solve(mf.open_model("test-8c"), "la"), other)
    run = CliRunner().invoke(cli, ["report", str(test_12c_files["la"]), str(other), "-o", str(tmp_path / "r.html")])
    assert run.exit_code == 1 and "cannot compare results of different models" in run.stderr
    assert not (tmp_path / "r.html").exists()
    model = tmp_path / "model.nc"
    mf.save(mf.open_model("test-12c"), model)
    run = CliRunner().invoke(cli, ["report", str(model), "-o", str(tmp_path / "r.html")])
    assert run.exit_code == 1 and "not a result or diagnosis file" in run.stderr
    run = CliRunner().invoke(cli, ["report", str(test_12c_files["la"]), "-o", str(test_12c_files["la"])])
    assert run.exit_code == 1


def test_ctrl_c_during_a_report_writes_nothing_and_exits_130(test_12c_files, tmp_path, monkeypatch, capsys):
    import masonryfw_compare.report as report_module
    from masonryfw.cli import main

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(report_module, "report_html", interrupted)
    out = tmp_path / "r.html"
    with pytest.raises(SystemExit) as stop:
        main(["report", str(test_12c_files["la"]), "-o", str(out)])
    assert stop.value.code == 130
    assert "interrupted: nothing written" in capsys.readouterr().err
    assert not out.exists() and list(tmp_path.iterdir()) == []
