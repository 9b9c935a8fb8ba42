"""``masonryfw report``: one self-contained HTML file about one or more results of a model.

Everything is inside the file: the figures are PNGs in ``data:`` URLs, the style
sheet is inline, there is no script and no link to the network, so it opens
anywhere and can be attached to an assessment. The numbers are the core's
(:func:`masonryfw.plugin_api.headline_rows`, :func:`masonryfw.plugin_api.score_rows`): each table cell
carries its full-precision value in ``data-value`` so that a reader (or a test)
can check it against the result files.
"""
from __future__ import annotations

import base64
import datetime
import html
import io
import itertools
import platform
from collections.abc import Callable, Sequence
from importlib import metadata

import numpy as np
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

from .block_plots import drawable_kinds
from .comparison import ensure_same_model

FIGURE_DPI = 130
#: Libraries whose versions the provenance lists.
LIBRARIES = ("numpy", "scipy", "xarray", "netCDF4", "matplotlib", "numba", "scikit-fem", "clarabel")

STYLE = """
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; margin: 2em auto; max-width: 70em;
       padding: 0 1em; color: #222; line-height: 1.4; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; } h2 { border-bottom: 1px solid #ccc; margin-top: 1.6em; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.92em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th { background: #f3f3f3; } td.note { color: #555; font-size: 0.9em; }
figure { margin: 1em 0; } figure img { max-width: 100%; height: auto; border: 1px solid #eee; }
figcaption { color: #555; font-size: 0.9em; } pre { background: #f7f7f7; padding: 0.6em; overflow-x: auto;
font-size: 0.85em; } .meta { color: #555; }
"""


def _png(figure) -> str:
    """A matplotlib figure as a ``data:`` URL of a PNG cropped to what is drawn."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=FIGURE_DPI, bbox_inches="tight", pad_inches=0.04)
    return "data:image/png;base64," + base64.b64encode(buffer.getvalue()).decode("ascii")


def _figure(datasets: Sequence[xr.Dataset], kind: str, caption: str, options: dict | None = None) -> str:
    src = _png(mf.render(list(datasets), kind, options or {}))
    return (f'<figure data-kind="{html.escape(kind)}"><img src="{src}" alt="{html.escape(caption)}">'
            f"<figcaption>{html.escape(caption)}</figcaption></figure>")


def _number(value, spec: str) -> str:
    """An attribute of a file as a number in format ``spec``; ``?`` when it is not one (a file can hold anything)."""
    try:
        return format(float(value), spec)
    except (TypeError, ValueError):
        return "?"


def _value_attribute(value: float | None) -> str:
    return "" if value is None else f' data-value="{value!r}"'


def _table(header: Sequence[str], rows: Sequence[mfp.Row], table_id: str, columns: Sequence[str]) -> str:
    """An HTML table of :class:`masonryfw.plugin_api.Row`; each cell says its row key, column and full value."""
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header) + "<th>what it means</th>"
    body = []
    for row in rows:
        cells = "".join(
            f'<td data-row="{html.escape(row.label)}" data-column="{html.escape(column)}"{_value_attribute(value)}>'
            f"{html.escape(cell)}</td>"
            for cell, value, column in zip(row.cells, row.values, columns)
        )
        body.append(f"<tr><th>{html.escape(row.label)}</th>{cells}<td class=\"note\">{html.escape(row.note)}</td></tr>")
    return f'<table id="{table_id}"><tr>{head}</tr>{"".join(body)}</table>'


def _model_of(result: xr.Dataset) -> xr.Dataset:
    """The model variables of a result, titled as the model (drawn as a model, not as a result)."""
    in_3d = mfp.space(result) == 3
    names = [n for n in result.data_vars if n in mfp.load_schema("model3d" if in_3d else "model")["variables"]]
    attrs = {"title": result.attrs.get("title", ""), **({"masonryfw_space": 3} if in_3d else {})}
    return xr.Dataset({n: result[n] for n in names}, attrs=attrs)


def _masonry_span(first: xr.Dataset, masonry: np.ndarray) -> str:
    """The masonry's extent: width x height of a wall, x by y by z of a 3D model."""
    if mfp.space(first) == 3:
        owner = np.repeat(np.arange(masonry.size), first.block_node_count.values)
        points = np.c_[first.node_x.values, first.node_y.values, first.node_z.values][masonry[owner]]
        return " x ".join(f"{v:.4g} m" for v in np.ptp(points, axis=0)) + " (x, y, z)"
    xmin, xmax, ymin, ymax = mfp.block_bounds(first.node_x, first.node_y, first.block_node_count)
    return f"{xmax[masonry].max() - xmin[masonry].min():.4g} m x {ymax[masonry].max() - ymin[masonry].min():.4g} m"


def _model_section(first: xr.Dataset) -> str:
    roles = first.block_role.values
    masonry = mfp.masonry_blocks(roles)
    facts = (f"{int(masonry.sum())} masonry blocks, {int(mfp.support_blocks(roles).sum())} supports, "
             f"{first.sizes.get('interface', 0)} interfaces; the masonry spans {_masonry_span(first, masonry)}.")
    caption = ("The model in axonometry: blocks by role." if mfp.space(first) == 3 else
               "The model: blocks by role (supports hatched, a settling one with an arrow), joints by kind.")
    parts = [f"<h2>The {'building' if mfp.space(first) == 3 else 'wall'}</h2>", f"<p>{html.escape(facts)}</p>",
             _figure([_model_of(first)], "model", caption)]
    if first.attrs.get("source_drawing"):
        parts.append(f"<p>Drawing: <code>{html.escape(str(first.attrs['source_drawing']))}</code>, sha256 "
                     f"<code>{html.escape(str(first.attrs.get('source_drawing_sha256', '?')))}</code></p>")
    if first.attrs.get("source_spec"):
        parts.append("<details open><summary>Source spec</summary><pre>"
                     f"{html.escape(str(first.attrs['source_spec']), quote=False)}</pre></details>")
    return "\n".join(parts)


def _mechanism_source(ds: xr.Dataset) -> str:
    """What a result's block motions are, in a few words (docs/format.md, block_displacement)."""
    if "qp_failure" not in ds:
        return "the final displacement" if "step_settlement" in ds else "the collapse mechanism"
    if "step_settlement" in ds or "step_load_factor" in ds:
        return "the continuum's displacement increment over its last steps, fitted per block"
    return "the continuum's collapse velocities from its limit LP, fitted per block"


def _forces_state(ds: xr.Dataset) -> str:
    """When a result's contact forces act: at the last record of an incremental run, else at collapse."""
    if "step_settlement" in ds and ds.step_settlement.size:
        return f"at the last record (settlement {1e3 * float(ds.step_settlement.values[-1]):.3g} mm)"
    return "at the last trial of the load-factor search" if "trial_load_factor" in ds else "at collapse"


def _result_figures(ds: xr.Dataset, label: str) -> list[str]:
    """The figures a single result supports, each with a caption saying how to read it."""
    captions = {
        "mechanism": f"the mechanism ({_mechanism_source(ds)}, amplified); the dominant macro-blocks numbered by "
                     "size, cracked joints heavy on the blocks' faces.",
        "cracks": ("the joints in the masonry that open at the last record, filled in the colour of their width's "
                   "damage category, each wall's widest ringed and listed (the building as built, see-through)."
                   if mfp.space(ds) == 3 and "step_crack_width_max" in ds else "joints that open, slide or both."),
        "forces": f"joint resultants {_forces_state(ds)}; colour: the share of the friction used.",
        "plastic": "plastic quadrature points of the continuum.",
        "ltsm": ("the engineers' stages 1 and 2 beside the model: the building's plan over the greenfield "
                 "settlement, each wall in the colour of its own LTSM category, and the LTSM charts of the worst "
                 "wall's parts at the assessed settlement." if "building_walls" in ds.attrs else
                 "the engineers' stages 1 and 2 beside the model: the greenfield trough under the wall, its sagging "
                 "and hogging parts, and the LTSM chart (deflection ratio against horizontal strain, the category "
                 "zones for the governing part) at the assessed settlement."),
    }
    return [_figure([ds], kind, f"{label}: {captions[kind]}") for kind in drawable_kinds(ds)]


def _history_section(datasets: Sequence[xr.Dataset]) -> list[str]:
    incremental = [ds for ds in datasets if "step_settlement" in ds]
    if not incremental:
        return []
    datasets = [ds for ds in datasets if "step_settlement" in ds or "collapse_multiplier" in ds]  # what it draws
    parts = ["<h2>Reaction against settlement</h2>",
             _figure(datasets, "history", "Reaction on the settling supports of every incremental result (over a "
                     "profile the settlement reaction: each segment's reaction weighted by how fast the ground under "
                     "it settles), with the dead reaction R0 and the limit analyses' collapse reaction (1 - alpha) R0; "
                     "strips along the top: the damage category."),
             _figure(datasets, "history", "The same on a logarithmic settlement axis (the first fractions of a "
                     "millimetre).", {"xscale": "log"})]
    if all("step_damage_category" in ds for ds in incremental):
        parts.append(_figure(incremental, "history", "Widest crack in the masonry against settlement, over the "
                             "bands of the damage categories.", {"quantity": "damage"}))
    tables = [(mf.result_label(ds), mf.capacity_text(ds)) for ds in incremental]
    if any(text for _, text in tables):
        parts.append("<h3>Where each damage category is first reached</h3>"
                     '<p class="note">From one run: the widest crack (stage 3) beside the limiting tensile strain '
                     "method (stage 2) and the greenfield screen (stage 1); over a tunnel also in volume loss "
                     "(S_max is proportional to it). <code>masonryfw capacity</code> runs it.</p>")
        parts += [f"<p>{html.escape(label)}</p><pre>{html.escape(text)}</pre>" for label, text in tables if text]
    return parts


def _agreement_section(datasets: Sequence[xr.Dataset], letters: Sequence[str]) -> list[str]:
    if len(datasets) < 2:
        return []
    pairs = list(itertools.combinations(range(len(datasets)), 2))
    comparisons = [mf.compare(datasets[i], datasets[j], "crack") for i, j in pairs]
    columns = [f"{letters[i]}-{letters[j]}" for i, j in pairs]
    side_by_side = _figure(datasets, "compare", "The results side by side, each later one with its scores against the "
                           "first.")
    return ["<h2>Agreement</h2>",
            "<p>Every pair scored by the <code>crack</code> comparator (the first of a pair is its reference): "
            "do the two results crack the same joints, break into the same pieces, move the same way?</p>",
            _table(["score", *columns], mfp.score_rows(comparisons), "agreement", columns), side_by_side]


def _versions() -> dict[str, str]:
    versions = {"masonryfw": mf.__version__, "python": platform.python_version()}
    for name in LIBRARIES:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            continue
    return versions


def _provenance_section(paths: Sequence[str], datasets: Sequence[xr.Dataset], letters: Sequence[str],
                        command: str) -> list[str]:
    rows = []
    for letter, path, ds in zip(letters, paths, datasets):
        digest = mfp.sha256_file(path)
        facts = {
            "file": path, "file sha256": digest, "solver": ds.attrs.get("solver", "?"),
            "solver version": ds.attrs.get("solver_version", "?"), "core version": ds.attrs.get("core_version", "?"),
            "options": ds.attrs.get("solver_options", "{}"), "model sha256": ds.attrs.get("model_sha256", "?"),
            "wall time": f"{_number(ds.attrs.get('wall_time_s'), '.3g')} s",
            "stop reason": ds.attrs.get("stop_reason", ""), "history": ds.attrs.get("history", ""),
        }
        cells = "".join(f"<tr><th>{html.escape(k)}</th><td><code>{html.escape(str(v))}</code></td></tr>"
                        for k, v in facts.items() if v != "")
        rows.append(f'<h3>{letter}: {html.escape(mf.result_label(ds))}</h3><table class="provenance">{cells}</table>')
    versions = "".join(f"<tr><th>{html.escape(k)}</th><td>{html.escape(v)}</td></tr>" for k, v in _versions().items())
    return ["<h2>Provenance</h2>", *rows, "<h3>This report</h3>",
            f"<p>Made by <code>{html.escape(command)}</code> on "
            f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC with:</p>",
            f"<table>{versions}</table>"]


def _diagnosis_section(path: str, ds: xr.Dataset) -> list[str]:
    """A settlement diagnosis (a ``diagnosis`` dataset): its verdict, the ranked candidates and its figure."""
    columns = list(mfp.DIAGNOSIS_COLUMNS)
    source = ", ".join(f"{k} <code>{html.escape(str(ds.attrs[a]))}</code>" for k, a in
                       (("cracks", "source_cracks"), ("levelling", "source_levelling")) if ds.attrs.get(a))
    made_by = (str(ds.attrs.get("history", "")).splitlines() or [""])[-1]
    facts = (f"{ds.sizes['candidate']} scenarios solved by {html.escape(str(ds.attrs.get('solver', '?')))} on ground "
             f"segments of {_number(ds.attrs.get('segment'), '.4g')} m "
             f"({int(ds.attrs.get('failed_candidates', 0))} could not be solved), scored against the survey "
             f"({source}); a surveyed line follows a joint within {_number(ds.attrs.get('tolerance'), '.3g')} m. "
             f"The plausible set: every candidate within {_number(ds.attrs.get('plausible_margin'), 'g')} of the "
             f"best score. File sha256 {mfp.sha256_file(path)}; made by: <code>{html.escape(made_by)}</code>")
    partial = (f'<p class="partial"><strong>Partial: the search was interrupted after '
               f"{ds.sizes['candidate'] + int(ds.attrs.get('failed_candidates', 0))} of "
               f"{int(ds.attrs.get('scenarios_planned', 0))} scenarios; the ranking is of those tried.</strong></p>"
               if int(ds.attrs.get("interrupted", 0)) else "")
    return [f"<h2>Diagnosis: {html.escape(path)}</h2>", partial,
            f"<p><strong>{html.escape(str(ds.attrs.get('verdict', '')))}</strong></p>", f"<p>{facts}</p>",
            _table(["rank", *columns], mfp.diagnosis_rows(ds, 10), "diagnosis", columns),
            _figure([ds], "diagnosis", "The surveyed cracks (red) over the wall, the best candidates' mechanisms "
                    "with the joints they crack (blue), every candidate's score by rank, and the Gaussian troughs' "
                    "scores over their centre and width.")]


def report_html(paths: Sequence[str], command: str, progress: Callable[[float, str], None] | None = None) -> str:
    """The report of the results at ``paths`` (one model), and of any diagnosis among them, as one HTML
    document."""
    step = progress or (lambda fraction, message: None)
    opened = [mf.open_checked(p) for p in paths]
    for path, ds in zip(paths, opened):
        if ds.attrs.get("masonryfw_format") not in ("result", "diagnosis"):
            raise mf.MasonryError(f"{path}: not a result or diagnosis file (masonryfw_format = "
                                  f"{ds.attrs.get('masonryfw_format')!r}); the report reads those")
    diagnoses = [(p, ds) for p, ds in zip(paths, opened) if ds.attrs.get("masonryfw_format") == "diagnosis"]
    paths = [p for p, ds in zip(paths, opened) if ds.attrs.get("masonryfw_format") == "result"]
    datasets = [ds for ds in opened if ds.attrs.get("masonryfw_format") == "result"]
    for ds in datasets[1:]:
        ensure_same_model(datasets[0], ds)
    letters = [chr(ord("A") + i) for i in range(len(datasets))]
    labels = [f"{letter}: {mf.result_label(ds)}" for letter, ds in zip(letters, datasets)]
    first = datasets[0] if datasets else diagnoses[0][1]
    title = str(first.attrs.get("title", "untitled"))
    step(0.05, "the wall")
    parts = [f"<h1>{html.escape(title)}</h1>",
             '<p class="meta">' + " &middot; ".join(
                 f"{html.escape(label)} (<code>{html.escape(path)}</code>)" for label, path in
                 [*zip(labels, paths), *(("diagnosis", p) for p, _ in diagnoses)]) + "</p>",
             _model_section(first)]
    if datasets:
        parts += ["<h2>Key numbers</h2>", _table(["", *letters], mfp.headline_rows(datasets), "key-numbers", letters)]
        r0 = mfp.r0_text(datasets, labels)
        parts += [f'<p class="note" id="r0-note">{html.escape(r0)}</p>'] if r0 else []
        damage = mf.damage_text(datasets, labels)
        parts += [f'<p class="note" id="damage-note">{html.escape(damage)}</p>'] if damage else []
    step(0.2, "figures")
    parts += _history_section(datasets)
    for i, (label, ds) in enumerate(zip(labels, datasets)):
        step(0.2 + 0.5 * i / len(datasets), f"figures of {label}")
        walls = mf.walls_text(ds)
        parts += [f"<h2>{html.escape(label)}</h2>", *([f'<pre class="walls">{html.escape(walls)}</pre>'] if walls else []),
                  *_result_figures(ds, label)]
    step(0.7, "diagnoses")
    for path, ds in diagnoses:
        parts += _diagnosis_section(path, ds)
    step(0.75, "agreement")
    parts += _agreement_section(datasets, letters)
    parts += _provenance_section(paths, datasets, letters, command)
    step(1.0, "done")
    body = "\n".join(parts)
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f'<meta name="viewport" content="width=device-width, initial-scale=1">'
            f"<title>{html.escape(title)} - masonryfw report</title><style>{STYLE}</style></head>"
            f"<body>\n{body}\n</body></html>\n")
