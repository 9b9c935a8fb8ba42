"""A second physics in the loop: the best candidates run forward by fdem to their magnitudes and scored on its cracks.

la ranks by its collapse mechanism, the joints that open per unit settlement; a real wall cracks like fdem
(elastic contacts, finite displacements): it follows a wide trough, bridges a narrow one and opens hairlines
the mechanism has not. The best candidates are solved forward from rest to their estimated settlement (from
the levelling or the widths; fdem's own default run where there is neither), the joints open or slipping
more than a hairline a surveyor sees (:data:`VISIBLE_WIDTH`) at the end are their cracks, weighted by their
motion, and scored against the survey as la's mechanisms are (:func:`.scoring.match`; with a levelling, fdem's
own course motion fitted as :mod:`.levelling` fits a mechanism's). The re-ranked lead the ranking in the order of
those scores, the best of them plausible; the plausible set is otherwise the search's (what the cracks and the
levelling allow). On the held-out surveys' tuning half (docs/diagnose.md) re-ranking the best five by fdem
put the truth's family first from cracks alone in 17 of 28 against la's 12.

How many: ``--rerank N``, or as many of the best :data:`DEFAULT_COUNT` as fit in ``--budget`` seconds by the
solver's estimate of one run.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

from . import levelling, scenarios, scoring
from .diagnosis import Candidate, Diagnosis, profile_of

#: A joint open or slipping more than this at the end is a crack a surveyor draws [m] (a hairline).
VISIBLE_WIDTH = 1e-4
#: The candidates re-ranked by default, if the budget allows.
DEFAULT_COUNT = 5
#: The default budget of the re-ranking [s].
DEFAULT_BUDGET = 120.0


def affordable(diagnosis: Diagnosis, budget: float, solver: str = "fdem", most: int = DEFAULT_COUNT) -> int:
    """How many of the best ``most`` candidates, in order, a re-ranking by ``solver`` runs within ``budget``
    seconds by the solver's estimate of each run (0 where it has no estimate)."""
    spent, count = 0.0, 0
    for candidate in diagnosis.candidates[:most]:
        estimate = mf.estimate(forward_model(diagnosis, candidate), solver, {})
        if estimate is None or not estimate.seconds > 0 or spent + estimate.seconds > budget:
            break
        spent, count = spent + estimate.seconds, count + 1
    return count


def forward_model(diagnosis: Diagnosis, candidate: Candidate) -> xr.Dataset:
    """The wall on its ground moved by ``candidate``'s profile, to its magnitude where it has one."""
    profile = profile_of(diagnosis, candidate.table)
    magnitude = candidate.score.magnitude
    if magnitude is not None and math.isfinite(magnitude) and magnitude > 0:
        profile = dataclasses.replace(profile, target=magnitude)
    return mf.over_profile(diagnosis.model, profile)


def visible_indicator(result: xr.Dataset) -> np.ndarray:
    """``(interface,)``: each joint's final opening or slip over the widest, where more than :data:`VISIBLE_WIDTH`
    (0 elsewhere)."""
    motion = np.maximum(np.abs(result.interface_opening.values), np.abs(result.interface_slip.values)).max(axis=1)
    widest = float(motion.max(initial=0.0))
    return np.where(motion > VISIBLE_WIDTH, motion / widest, 0.0) if widest > VISIBLE_WIDTH else np.zeros_like(motion)


def forward_score(diagnosis: Diagnosis, result: xr.Dataset) -> float:
    """A forward run's score: its visible cracks against the survey, with its course motion against the
    levelling (the geometric mean, as the search's) where there is one."""
    crack = scoring.match(diagnosis.wall, diagnosis.observed, visible_indicator(result)).crack
    levelled = diagnosis.survey.levelling
    if levelled is None:
        return crack
    settled = float(result.step_settlement.values[-1]) if "step_settlement" in result else 1.0
    motion = scoring.vertical_motion(result, levelled[:, 0], levelled[:, 1]) / max(settled, 1e-12)
    fit = levelling.fit(levelled[:, 2], motion, np.zeros_like(motion), diagnosis.sigma)
    best = min(c.score.fit.residual for c in diagnosis.candidates)
    noise = len(levelled) * diagnosis.sigma**2 + 1e-30
    return math.sqrt(crack * min(1.0, (best + noise) / (fit.residual + noise)))


def rerank(diagnosis: Diagnosis, count: int, solver: str = "fdem", progress=mfp.no_progress) -> None:
    """Run the best ``count`` candidates forward by ``solver``, score them on its cracks and put them first in the
    order of those scores (module docstring); Ctrl-C keeps those finished."""
    chosen = diagnosis.candidates[:count]
    try:
        for k, candidate in enumerate(chosen):
            progress(k / max(count, 1), f"re-rank: {scenarios.describe(candidate.table)} with {solver}")
            try:
                result = mf.solve(forward_model(diagnosis, candidate), solver, {})
            except mf.MasonryError as exc:
                diagnosis.rerank_failed.append((candidate.table, f"{solver}: {str(exc).splitlines()[0]}"))
                continue
            if int(result.attrs.get("interrupted", 0)):
                raise KeyboardInterrupt
            candidate.reranked = forward_score(diagnosis, result)
    except KeyboardInterrupt:
        diagnosis.rerank_interrupted = True
    done = [c for c in chosen if c.reranked is not None]
    if not done:
        return
    done.sort(key=lambda c: -c.reranked)
    rest = [c for c in diagnosis.candidates if c.reranked is None]
    diagnosis.candidates[:] = done + rest
    for number, candidate in enumerate(diagnosis.candidates, start=1):
        candidate.rank = number
    done[0].plausible = True
    diagnosis.ranked_by, diagnosis.reranked = solver, len(done)
    progress(1.0, "re-rank: done")
