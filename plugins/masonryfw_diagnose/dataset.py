"""A diagnosis as a dataset (kind ``diagnosis``, ``schemas/diagnosis-2.json``) and as the ``--json`` contract.

The dataset holds the wall on its ground (the model variables, set under the best candidate's profile, so
``masonryfw solve diagnosis.nc`` would not do: ``masonryfw diagnose`` prints the table to paste), every
candidate ranked best first, the best candidates' mechanisms (what the ``diagnosis`` plot draws) and the
survey they were scored against. The JSON object is a contract others rely on:
``candidates`` (``rank``, ``settlement``, ``score``, ``plausible``, ``magnitude``), ``observed_joints``,
``unmatched_cracks``; the rest of its keys say more of the same.
"""
from __future__ import annotations

import json

import numpy as np
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

from . import scenarios
from .diagnosis import EXPLAINED, KEPT, PLAUSIBLE_MARGIN, Diagnosis, profile_of
from .scoring import SURVEY_THRESHOLD

TABLE_KEYS = ("start", "end", "center", "width")


def _nan(value) -> float:
    return float("nan") if value is None else float(value)


def _candidate_variables(diagnosis: Diagnosis) -> dict:
    candidates = diagnosis.candidates
    verified = [c.verified or {} for c in candidates]
    columns = {
        "candidate_profile": np.array([c.table["profile"] for c in candidates], dtype=object),
        **{f"candidate_{key}": np.array([_nan(c.table.get(key)) for c in candidates]) for key in TABLE_KEYS},
        "candidate_score": np.array([c.score.total for c in candidates]),
        "candidate_crack_score": np.array([c.score.crack for c in candidates]),
        "candidate_precision": np.array([c.score.precision for c in candidates]),
        "candidate_recall": np.array([c.score.recall for c in candidates]),
        "candidate_magnitude": np.array([_nan(c.score.magnitude) for c in candidates]),
        "candidate_plausible": np.array([c.plausible for c in candidates], dtype=np.int8),
        "candidate_unexplained_cracks": np.array([len(c.score.unexplained) for c in candidates], dtype=np.int32),
        "candidate_unobserved_joints": np.array([c.score.unobserved for c in candidates], dtype=np.int32),
    }
    if diagnosis.survey.levelling is not None:
        columns["candidate_levelling_score"] = np.array([_nan(c.score.levelling) for c in candidates])
        columns["candidate_magnitude_spread"] = np.array([c.score.fit.spread for c in candidates])
        columns["candidate_ground_share"] = np.array([c.score.fit.share_ground for c in candidates])
    if diagnosis.reranked:
        columns["candidate_reranked_score"] = np.array([_nan(c.reranked) for c in candidates])
    if any(verified):
        columns["candidate_verified_crack_width"] = np.array([_nan(v.get("crack_width")) for v in verified])
        columns["candidate_verified_damage_category"] = np.array(
            [-1 if v.get("damage_category") is None else int(v["damage_category"]) for v in verified], dtype=np.int8)
        columns["candidate_verified_minimum_reaction"] = np.array([_nan(v.get("minimum_reaction")) for v in verified])
    return {name: ("candidate", values, mfp.variable_attrs(name, "diagnosis")) for name, values in columns.items()}


def _kept_variables(diagnosis: Diagnosis) -> dict:
    kept = [c for c in diagnosis.candidates if c.result is not None]
    columns = {
        "kept_candidate": (("kept",), np.array([c.rank - 1 for c in kept], dtype=np.int32)),
        "kept_block_displacement": (("kept", "block", "axis"),
                                    np.stack([c.result.block_displacement.values for c in kept])),
        "kept_block_rotation": (("kept", "block"), np.stack([c.result.block_rotation.values for c in kept])),
        "kept_crack_indicator": (("kept", "interface"), np.stack(
            [mfp.indicator_at(c.result, SURVEY_THRESHOLD) for c in kept])),
    }
    if diagnosis.survey.levelling is not None:
        columns["kept_levelling_fit"] = (("kept", "levelling_point"), np.stack([c.score.fit.fitted for c in kept]))
    return {name: (dims, values, mfp.variable_attrs(name, "diagnosis")) for name, (dims, values) in columns.items()}


def _survey_variables(diagnosis: Diagnosis) -> dict:
    survey, best = diagnosis.survey, diagnosis.best.score
    unmatched = set(diagnosis.observed.unmatched)
    columns = {
        "survey_crack_name": (("survey_crack",), np.array(survey.names, dtype=object)),
        "survey_crack_width": (("survey_crack",), np.array([_nan(w) * 1e-3 for w in survey.widths_mm])),
        "survey_crack_matched": (("survey_crack",), np.array([k not in unmatched for k in range(len(survey.names))],
                                                             dtype=np.int8)),
        "survey_crack_explained": (("survey_crack",), np.array(
            [k not in best.unexplained for k in range(len(survey.names))], dtype=np.int8)),
        "survey_point_x": (("survey_point",), np.concatenate([line[:, 0] for line in survey.cracks])),
        "survey_point_y": (("survey_point",), np.concatenate([line[:, 1] for line in survey.cracks])),
        "survey_point_crack": (("survey_point",), np.repeat(np.arange(len(survey.cracks), dtype=np.int32),
                                                            [len(line) for line in survey.cracks])),
        "observed_joint": (("interface",), np.isin(np.arange(diagnosis.model.sizes["interface"]),
                                                   diagnosis.observed.joints).astype(np.int8)),
    }
    if survey.levelling is not None:
        for k, name in enumerate(("levelling_x", "levelling_y", "levelling_dy")):
            columns[name] = (("levelling_point",), survey.levelling[:, k])
        columns["free_profile_x"] = (("free_node",), diagnosis.free.x)
        columns["free_profile_settlement"] = (("free_node",), diagnosis.free.settlement)
    return {name: (dims, values, mfp.variable_attrs(name, "diagnosis")) for name, (dims, values) in columns.items()}


def to_dataset(diagnosis: Diagnosis, source_wall: str = "") -> xr.Dataset:
    """The diagnosis as a ``diagnosis`` dataset (module docstring)."""
    model = mf.over_profile(diagnosis.model, profile_of(diagnosis, diagnosis.best.table))
    names = [n for n in model.data_vars if n in mfp.load_schema("model")["variables"]]
    survey = diagnosis.survey
    attrs = {
        **{k: v for k, v in model.attrs.items() if k in ("title", "source_spec", "source_drawing",
                                                          "source_drawing_sha256", "settlement_profile")},
        **mfp.format_header("diagnosis"),
        "solver": diagnosis.solver, "solver_version": mfp.solver_version(diagnosis.solver),
        "segment": diagnosis.segment, "tolerance": diagnosis.wall.tolerance, "unit_height": diagnosis.wall.unit_height,
        "plausible_margin": PLAUSIBLE_MARGIN, "explained_threshold": EXPLAINED, "verdict": diagnosis.verdict(),
        "families": ",".join(diagnosis.families), "failed_candidates": len(diagnosis.failed),
        "source_cracks": survey.sources.get("cracks", ""), "survey_unit": survey.sources.get("unit", "m"),
        "ranked_by": diagnosis.ranked_by or diagnosis.solver,
    }
    if source_wall:
        attrs["source_wall"] = source_wall
    if survey.sources.get("levelling"):
        attrs["source_levelling"] = survey.sources["levelling"]
    if diagnosis.verified_with:
        attrs["verify_solver"] = diagnosis.verified_with
    attrs.update(_determined_attrs(diagnosis))
    if survey.levelling is not None:
        attrs["levelling_sigma"] = diagnosis.sigma
        attrs["levelling_sigma_given"] = int(diagnosis.sigma_given)
        attrs.update({f"levelling_probability_{f}": p for f, p in diagnosis.family_probability.items()})
    if diagnosis.reranked:
        attrs["reranked"] = diagnosis.reranked
    if diagnosis.interrupted:  # a partial search: its figures and reports say so
        attrs["interrupted"] = 1
        attrs["scenarios_planned"] = len(diagnosis.tables)
    return xr.Dataset({**{n: model[n] for n in names}, **_candidate_variables(diagnosis),
                       **_kept_variables(diagnosis), **_survey_variables(diagnosis)},
                      coords={c: model.coords[c] for c in model.coords}, attrs=attrs)


def _determined_attrs(diagnosis: Diagnosis) -> dict:
    determined = diagnosis.determined()
    attrs = {"determined_side": determined.side or "undetermined", "determined_edge": determined.edge_best,
             "determined_edge_low": determined.edge[0], "determined_edge_high": determined.edge[1],
             "determined_mode": determined.mode or "undetermined", "determined_families": ",".join(determined.families)}
    if determined.magnitude is not None:
        attrs.update(determined_magnitude=determined.magnitude_best, determined_magnitude_low=determined.magnitude[0],
                     determined_magnitude_high=determined.magnitude[1])
    return attrs


def settlement_table(table: dict) -> dict:
    """A candidate's ``[settlement]`` keys as the JSON contract gives them (lengths in metres, rounded to a
    micrometre so a pasted table reads cleanly)."""
    return {key: (round(value, 6) if isinstance(value, float) else value) for key, value in table.items()}


def _finite(value: float | None) -> float | None:
    return None if value is None or not np.isfinite(value) else float(value)


def candidate_json(diagnosis: Diagnosis, candidate) -> dict:
    x_a, x_b = diagnosis.extent
    entry = {"rank": candidate.rank, "settlement": settlement_table(candidate.table),
             "score": round(candidate.score.total, 6), "plausible": bool(candidate.plausible),
             "magnitude": _finite(candidate.score.magnitude),
             "description": scenarios.describe(candidate.table), "shape": scenarios.shape(candidate.table, x_a, x_b),
             "crack_score": round(candidate.score.crack, 6), "precision": round(candidate.score.precision, 6),
             "recall": round(candidate.score.recall, 6),
             "levelling_score": None if candidate.score.levelling is None else round(candidate.score.levelling, 6),
             "unexplained_cracks": [diagnosis.survey.names[k] for k in candidate.score.unexplained],
             "unobserved_joints": candidate.score.unobserved}
    if candidate.score.fit is not None:
        entry["magnitude_spread"] = _finite(candidate.score.fit.spread)
        entry["ground_share"] = round(candidate.score.fit.share_ground, 6)
    if candidate.reranked is not None:
        entry["reranked_score"] = round(candidate.reranked, 6)
    if candidate.verified:
        entry["verified"] = {k: _finite(v) if isinstance(v, float) else v for k, v in candidate.verified.items()}
    return entry


def to_json(diagnosis: Diagnosis, top: int) -> dict:
    """The ``--json`` object: the best ``top`` candidates, and every plausible one beyond them."""
    shown = max(top, sum(c.plausible for c in diagnosis.candidates))
    return {"candidates": [candidate_json(diagnosis, c) for c in diagnosis.candidates[:shown]],
            "observed_joints": int(diagnosis.observed.joints.size),
            "unmatched_cracks": len(diagnosis.observed.unmatched),
            "unmatched_crack_names": [diagnosis.survey.names[k] for k in diagnosis.observed.unmatched],
            "verdict": diagnosis.verdict(), "explained": diagnosis.explained,
            "plausible": sum(c.plausible for c in diagnosis.candidates), "tried": len(diagnosis.candidates),
            "failed": len(diagnosis.failed), "segment": diagnosis.segment, "tolerance": diagnosis.wall.tolerance,
            "solver": diagnosis.solver, "families": list(diagnosis.families), "kept": KEPT,
            "determined": diagnosis.determined().as_json(), "levelling": _levelling_json(diagnosis),
            "ranked_by": diagnosis.ranked_by or diagnosis.solver, "reranked": diagnosis.reranked}


def _levelling_json(diagnosis: Diagnosis) -> dict | None:
    """The ``levelling`` object: the noise, the families' probabilities, the free profile (null without one)."""
    if diagnosis.free is None:
        return None
    free = diagnosis.free
    return {"sigma": diagnosis.sigma, "sigma_given": diagnosis.sigma_given,
            "family_probability": {f: round(p, 6) for f, p in diagnosis.family_probability.items()},
            "free_profile": {"points": [[round(float(x), 6), round(float(s), 7)] for x, s in zip(free.x, free.settlement)],
                             "magnitude": free.magnitude, "sigma": free.sigma, "settlement": free.table()}}


def json_text(diagnosis: Diagnosis, top: int) -> str:
    return json.dumps(to_json(diagnosis, top), indent=1, allow_nan=False)
