"""From a crack survey back to the settlement that caused it: scenarios tried, scored and ranked.

The wall (a bundled case, a spec, parametric or drawn, or a model file) is put on its ground (its support
blocks merged, or one made under its lowest masonry) cut into segments (``mf.ground_model``; its own support
kinematics, profile and loading set aside).
Every scenario (:mod:`.scenarios`) moves that ground (``mf.over_profile``) and is solved by the chosen
solver, la by default: la's collapse mechanism is where a dry-joint wall opens as soon as the ground moves,
so its cracks are the pattern to match (docs/diagnose.md states this assumption and its limits). Each is
scored against the survey (:mod:`.scoring`); the candidates are ranked best first, and every candidate within
``PLAUSIBLE_MARGIN`` of the best's score is in the *plausible set*, the honest uncertainty.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

from . import features, levelling, parallel, scenarios, scoring
from .survey import UNITS, Survey

#: A candidate within this score of the best of its family is plausible, if its family is.
PLAUSIBLE_MARGIN = 0.05
#: A family is plausible, from cracks alone, when its best candidate is within this score of the best; the
#: held-out survey's tuning half (docs/diagnose.md): at the 0.05 of a candidate the truth's family was in the
#: plausible set in 18 of 28, at 0.1 in 22 (0.15 and 0.25 add none and name every family).
FAMILY_MARGIN = 0.1
#: A family is plausible, with a levelling, when its probability by the levelling's evidence is at least this
#: (a Bayes factor of 1 to 19 against the others).
FAMILY_EVIDENCE = 0.05
#: A best score under this explains the survey poorly: the diagnosis says so.
EXPLAINED = 0.5
#: The best candidates whose mechanisms are kept (and drawn, and verified).
KEPT = 3
#: The most scenarios a search tries: Facade 3's full search tries 1,339; the steps grow with the square of the
#: ground pieces (a millimetre's segment under a 1.5 m wall would make 1.1 million).
MAX_SCENARIOS = 20_000


@dataclass
class Candidate:
    table: dict
    score: scoring.Score
    rank: int = 0
    plausible: bool = False
    result: xr.Dataset | None = None  # kept for the best few
    verified: dict | None = None  # the forward run of --verify: its numbers
    reranked: float | None = None  # its score from a forward run by the re-ranking's physics


@dataclass
class Diagnosis:
    model: xr.Dataset  # the wall on its ground segments, every segment held
    survey: Survey
    wall: scoring.WallJoints
    observed: scoring.Observed
    candidates: list[Candidate]  # ranked, best first
    solver: str
    segment: float
    families: tuple[str, ...]
    extent: tuple[float, float]  # the ground's ends x_a, x_b [m]
    unit_length: float  # the median masonry block length [m]
    segment_given: bool = False
    failed: list[tuple[dict, str]] = field(default_factory=list)
    verified_with: str = ""
    interrupted: bool = False  # Ctrl-C stopped the search: the candidates are those tried before
    tables: list[dict] = field(default_factory=list)  # the scenarios to try
    expected: mfp.Estimate | None = None  # the search's time, before it starts
    verify_interrupted: bool = False  # Ctrl-C stopped the verification: the verified are those finished before
    sigma: float = 0.0  # the levelling's noise [m]: given, or read from the data (levelling.noise)
    sigma_given: bool = False
    free: levelling.FreeProfile | None = None  # the free ground profile fitted to the levelling
    family_probability: dict[str, float] = field(default_factory=dict)  # from the levelling's evidence
    ranked_by: str = ""  # the physics whose cracks ranked the best candidates (the search's solver, or fdem)
    reranked: int = 0  # how many of the best were re-ranked by a forward run
    rerank_interrupted: bool = False  # Ctrl-C stopped the re-ranking: the re-ranked are those finished before
    rerank_failed: list[tuple[dict, str]] = field(default_factory=list)  # forward runs that failed, and why

    @property
    def best(self) -> Candidate:
        return self.candidates[0]

    @property
    def plausible(self) -> list[Candidate]:
        return [c for c in self.candidates if c.plausible]

    @property
    def explained(self) -> bool:
        return self.best.score.total >= EXPLAINED

    def determined(self) -> features.Determined:
        """What the plausible set agrees on: the settled side, the edge, sagging or hogging, the magnitude
        (:mod:`.features`; with a levelling, the magnitude of the plausible candidate that fits it best: the
        levelling measures it, the cracks do not)."""
        plausible = self.plausible
        if self.survey.levelling is not None:
            fitting = max(plausible, key=lambda c: c.score.levelling or 0.0)
            plausible = [fitting] + [c for c in plausible if c is not fitting]
        spreads = [c.score.fit.spread if c.score.fit is not None else 0.0 for c in plausible]
        determined = features.determine([c.table for c in plausible], [c.score.magnitude for c in plausible],
                                        self.extent, spreads)
        best = features.feature(self.best.table, self.extent)
        return dataclasses.replace(determined, edge_best=best.edge,
                                   families=tuple(dict.fromkeys(c.table["profile"] for c in self.plausible)))

    def verdict(self) -> str:
        count = len(self.plausible)
        if not self.explained:
            return (f"nothing tried explains these cracks well: the best score is {self.best.score.total:.2f} "
                    f"(under {EXPLAINED}), and {count} candidates are plausible")
        return (f"{features.sentence(self.determined(), self.survey.levelling is not None)} "
                f"[best: {scenarios.describe(self.best.table)}, score {self.best.score.total:.2f}; {count} plausible "
                f"candidate(s); ranked by {self.ranked_by or self.solver}]")


def wall_model(source: str) -> xr.Dataset:
    """The wall to diagnose: a bundled case, a model file or a spec (parametric or drawn), which may leave out
    its supports, ``[settlement]`` and ``[loading]`` (:func:`masonryfw.load_wall`): the diagnosis sets them aside
    and makes its ground."""
    path = Path(source)
    if path.is_file() and mfp.is_spec(path):
        return mf.build(mf.load_wall(path))
    return mf.open_model(source)


def check_survey(survey: Survey, model: xr.Dataset, margin: float) -> None:
    """Refuse cracks and levelling points further than ``margin`` off the wall's masonry (a wrong unit, another
    drawing's coordinates), naming the item, the wall's extent and the unit."""
    masonry = mfp.masonry_blocks(model.block_role.values)
    xmin, xmax, ymin, ymax = mfp.block_bounds(model.node_x.values, model.node_y.values, model.block_node_count.values)
    wall = (xmin[masonry].min(), xmax[masonry].max(), ymin[masonry].min(), ymax[masonry].max())
    unit = survey.sources.get("unit", "m")
    scale = {"m": 1.0, "cm": 0.01, "mm": 0.001}[unit]
    extent = f"x {wall[0] / scale:.6g}..{wall[1] / scale:.6g}, y {wall[2] / scale:.6g}..{wall[3] / scale:.6g} {unit}"

    def off(points: np.ndarray) -> np.ndarray:
        return ((points[:, 0] < wall[0] - margin) | (points[:, 0] > wall[1] + margin)
                | (points[:, 1] < wall[2] - margin) | (points[:, 1] > wall[3] + margin))

    for name, line in zip(survey.names, survey.cracks):
        outside = off(line)
        if outside.any():
            x, y = line[np.argmax(outside)] / scale
            raise mf.SpecError(f"crack map {survey.sources.get('cracks', '')!r}: crack {name!r} passes ({x:.6g}, "
                               f"{y:.6g}) {unit}, off the wall ({extent}); a wrong --unit or another drawing's "
                               "coordinates?")
    if survey.levelling is not None and off(survey.levelling).any():
        row = int(np.argmax(off(survey.levelling)))
        x, y = survey.levelling[row, :2] / scale
        raise mf.SpecError(f"levelling {survey.sources.get('levelling', '')!r} row {row + 2}: the point ({x:.6g}, "
                           f"{y:.6g}) {unit} is off the wall ({extent})")
    height = wall[3] - wall[2]
    if survey.levelling is not None and (np.abs(survey.levelling[:, 2]) > height).any():
        row = int(np.argmax(np.abs(survey.levelling[:, 2]) > height))
        raise mf.SpecError(f"levelling {survey.sources.get('levelling', '')!r} row {row + 2}: dy = "
                           f"{survey.levelling[row, 2] / scale:.6g} {unit} is more than the wall is high "
                           f"({height / scale:.6g} {unit}); a levelling measures millimetres")
    _refuse_a_map_in_another_unit(survey, wall, unit, scale)


def _refuse_a_map_in_another_unit(survey: Survey, wall: tuple, unit: str, scale: float) -> None:
    """A map a thousand (or a hundred) times smaller than the wall, which would fit the wall in another unit, was
    given in that unit: every line then lies in a corner, far from the wall's joints, and nothing explains it."""
    points = np.concatenate(survey.cracks)
    span = np.ptp(points, axis=0).max()
    size = max(wall[1] - wall[0], wall[3] - wall[2])
    if span >= size / 50:
        return
    for other, factor in UNITS.items():
        moved = points * factor / scale
        fits = (moved[:, 0].min() >= wall[0] - 0.01 * size and moved[:, 0].max() <= wall[1] + 0.01 * size
                and moved[:, 1].min() >= wall[2] - 0.01 * size and moved[:, 1].max() <= wall[3] + 0.01 * size)
        if factor > scale and fits and np.ptp(moved, axis=0).max() >= size / 10:
            raise mf.SpecError(f"crack map {survey.sources.get('cracks', '')!r}: read in {unit}, its lines span "
                               f"{span / scale:.3g} {unit} of a wall {size / scale:.6g} {unit} across, far from its "
                               f"joints; in {other} they cover the wall: give --unit {other}")


def ground_pieces(model: xr.Dataset) -> np.ndarray:
    """``(n, 2)``: the x-extent of every ground piece (support block), left to right."""
    ground = mfp.support_blocks(model.block_role.values)
    xmin, xmax, _, _ = mfp.block_bounds(model.node_x.values, model.node_y.values, model.block_node_count.values)
    pieces = np.round(np.c_[xmin[ground], xmax[ground]], 12)
    return pieces[np.lexsort(pieces.T[::-1])]


def diagnose(model: xr.Dataset, survey: Survey, families=scenarios.FAMILIES, segment: float | None = None,
             solver: str = "la", options: dict | None = None, tolerance: float | None = None,
             progress=mfp.no_progress, sigma: float | None = None) -> Diagnosis:
    """Try every scenario of ``families`` on ``model``'s wall and rank them against ``survey`` (module docstring):
    :func:`search` of :func:`prepare`."""
    return search(prepare(model, survey, families, segment, solver, options, tolerance, sigma), options, progress)


def prepare(model: xr.Dataset, survey: Survey, families=scenarios.FAMILIES, segment: float | None = None,
            solver: str = "la", options: dict | None = None, tolerance: float | None = None,
            sigma: float | None = None) -> Diagnosis:
    """The wall on its ground, the survey matched to its joints, the free profile of its levelling, the scenarios
    to try and the search's estimated time: nothing solved yet. Refused beyond :data:`MAX_SCENARIOS`
    scenarios, saying which ``--segment`` fits.

    ``segment`` defaults to the median masonry block length (about a unit length); ``tolerance`` (how far a
    surveyed line may lie from the joint it follows) to half the median block height; ``sigma`` (the
    levelling's noise [m]) to what the data say (:func:`.levelling.noise`).
    """
    masonry = mfp.masonry_blocks(model.block_role.values)
    xmin, xmax, _, _ = mfp.block_bounds(model.node_x.values, model.node_y.values, model.block_node_count.values)
    unit_length = float(np.median(xmax[masonry] - xmin[masonry]))
    segment_given = segment is not None
    segment = unit_length if segment is None else segment
    ground = mf.ground_model(model, segment, "--segment")
    pieces = ground_pieces(ground)
    _refuse_too_many(scenarios.count(pieces, tuple(families)), pieces, segment, families)
    wall = scoring.wall_joints(ground, tolerance)
    check_survey(survey, ground, max(wall.tolerance, wall.unit_height))
    observed = scoring.observe(wall, survey.cracks)
    diagnosis = Diagnosis(ground, survey, wall, observed, [], solver, segment, tuple(families),
                          (float(pieces.min()), float(pieces.max())), unit_length, segment_given)
    if survey.levelling is not None:
        x, dy = survey.levelling[:, 0], survey.levelling[:, 2]
        diagnosis.sigma, diagnosis.sigma_given = (levelling.noise(x, dy), False) if sigma is None else (sigma, True)
        diagnosis.free = levelling.free_profile(x, dy, np.unique(pieces), diagnosis.sigma)
    diagnosis.tables = scenarios.candidates(pieces, diagnosis.families, segment)
    one = mf.estimate(mf.over_profile(ground, profile_of(diagnosis, diagnosis.tables[0])), solver, options or {})
    if one is not None:
        diagnosis.expected = dataclasses.replace(
            one, seconds=one.seconds * len(diagnosis.tables),
            basis=f"{len(diagnosis.tables):,} scenarios of {one.basis}")
    return diagnosis


def _refuse_too_many(count: int, pieces: np.ndarray, segment: float, families) -> None:
    if count <= MAX_SCENARIOS:
        return
    n = len(pieces)
    per_piece = (count - (n * (n + 1) // 2 - 1)) / n  # the troughs and tilts grow with the pieces, the steps as n^2/2
    fits = -(0.5 + per_piece) + math.sqrt((0.5 + per_piece) ** 2 + 2 * (MAX_SCENARIOS + 1))
    fitting = 1.05 * segment * n / fits  # the pieces a segment leaves round to whole ones: a margin
    raise mf.SpecError(f"diagnose: --segment = {segment:.3g} m cuts the ground into {len(pieces):,} pieces, which "
                       f"make about {count:,} scenarios of {', '.join(families)} (the steps grow with the square of "
                       f"the pieces), over the {MAX_SCENARIOS:,} a search tries; give --segment of at least "
                       f"{fitting:.3g} m, or fewer --profiles")


def search(diagnosis: Diagnosis, options: dict | None = None, progress=mfp.no_progress,
           runner: parallel.Runner = parallel.serial) -> Diagnosis:
    """Solve and score every scenario of a prepared ``diagnosis`` (here, or by ``runner``: on local processes or a
    dask cluster, :mod:`.parallel`), then rank them; Ctrl-C ends the search with those tried (``interrupted``), or
    propagates when none was."""
    tables = diagnosis.tables
    done = 0
    try:
        for outcomes in runner(parallel.work(tried, diagnosis, options), parallel.chunks(tables, runner)):
            for table, score, failure in outcomes:
                done += 1
                progress(done / len(tables), f"diagnose: {scenarios.describe(table)} ({done} of {len(tables)})")
                if score is None:
                    diagnosis.failed.append((table, failure))
                else:
                    diagnosis.candidates.append(Candidate(table, score))
    except KeyboardInterrupt:
        if not diagnosis.candidates:
            raise
        diagnosis.interrupted = True
    if not diagnosis.candidates:
        raise mf.SolveError(f"diagnose: no scenario could be solved ({diagnosis.failed[0][1]})")
    rank(diagnosis)
    for candidate in diagnosis.candidates[:KEPT]:
        candidate.result = solved(diagnosis, candidate.table, options)
    progress(1.0, "diagnose: ranked")
    return diagnosis


def tried(diagnosis: Diagnosis, options: dict | None, tables: list[dict]) -> list[tuple[dict, scoring.Score | None,
                                                                                       str]]:
    """``(table, score, "")`` of every scenario of ``tables`` solved and scored, ``(table, None, why)`` of one that
    could not be solved."""
    outcomes: list[tuple[dict, scoring.Score | None, str]] = []
    for table in tables:
        try:
            result = solved(diagnosis, table, options)
        except mf.MasonryError as exc:
            outcomes.append((table, None, str(exc).splitlines()[0]))
            continue
        outcomes.append((table, score_of(diagnosis, table, result), ""))
    return outcomes


def score_of(diagnosis: Diagnosis, table: dict, result: xr.Dataset) -> scoring.Score:
    """How well a scenario's ``result`` (per unit settlement) explains the survey: its cracks, and its fit to the
    levelling (the ground's rate under every levelled point from the candidate's profile)."""
    levelled = diagnosis.survey.levelling
    rate = None if levelled is None else profile_of(diagnosis, table).rate(levelled[:, 0])
    return scoring.score(diagnosis.wall, diagnosis.observed, result, diagnosis.survey.widths_mm, levelled, rate,
                         diagnosis.sigma)


def rank(diagnosis: Diagnosis) -> None:
    """With a levelling, every candidate's levelling score against the best fit and the families' probabilities
    (:mod:`.levelling`); then :func:`order` the candidates."""
    candidates, levelled = diagnosis.candidates, diagnosis.survey.levelling
    if levelled is not None:
        fits = [c.score.fit for c in candidates]
        for candidate, value in zip(candidates, levelling.scores(fits, diagnosis.sigma, len(levelled))):
            candidate.score = dataclasses.replace(candidate.score, levelling=float(value))
        diagnosis.family_probability = levelling.family_probabilities(
            fits, [c.table["profile"] for c in candidates], diagnosis.sigma, len(levelled))
    order(candidates, diagnosis.family_probability)


def order(candidates: list[Candidate], family_probability: dict[str, float] | None = None) -> None:
    """Sort best first (ties: step before gaussian before linear, then as tried) and mark the plausible set: the
    candidates within :data:`PLAUSIBLE_MARGIN` of the best of their family, in the families the data cannot rule
    out (with a levelling, a probability of at least :data:`FAMILY_EVIDENCE`; from cracks alone, a best within
    :data:`FAMILY_MARGIN` of the best)."""
    precedence = {family: i for i, family in enumerate(scenarios.FAMILIES)}
    candidates.sort(key=lambda c: (-round(c.score.total, 12), precedence[c.table["profile"]]))
    best_of: dict[str, float] = {}
    for candidate in candidates:
        best_of.setdefault(candidate.table["profile"], candidate.score.total)
    if family_probability:
        families = {f for f in best_of if family_probability.get(f, 0.0) >= FAMILY_EVIDENCE}
    else:
        families = {f for f, score in best_of.items() if score >= candidates[0].score.total - FAMILY_MARGIN}
    for number, candidate in enumerate(candidates, start=1):
        family = candidate.table["profile"]
        candidate.rank = number
        candidate.plausible = family in families and candidate.score.total >= best_of[family] - PLAUSIBLE_MARGIN
    candidates[0].plausible = True


def profile_of(diagnosis: Diagnosis, table: dict) -> mf.Profile:
    """The profile a candidate's ``[settlement]`` table describes under the diagnosed wall."""
    return mf.settlement_profile(table, *diagnosis.extent, diagnosis.unit_length)


def solved(diagnosis: Diagnosis, table: dict, options: dict | None) -> xr.Dataset:
    """The wall on its ground moved as the ``[settlement]`` ``table`` says, solved by the diagnosis's solver."""
    return mf.solve(mf.over_profile(diagnosis.model, profile_of(diagnosis, table)), diagnosis.solver, options or {})


def verify(diagnosis: Diagnosis, solver: str = "fdem", count: int = KEPT, progress=mfp.no_progress) -> None:
    """Run the best ``count`` candidates that have a magnitude forward with ``solver`` to that settlement (the
    model's ``settlement_target``): their widest crack, damage category and smallest reaction go into
    ``candidate.verified``."""
    diagnosis.verified_with = solver
    try:
        for k, candidate in enumerate(diagnosis.candidates[:count]):
            magnitude = candidate.score.magnitude
            if magnitude is None or not magnitude > 0 or not math.isfinite(magnitude):
                continue
            progress(k / count, f"verify: {scenarios.describe(candidate.table)} with {solver} to "
                                f"{1e3 * magnitude:.3g} mm")
            profile = dataclasses.replace(profile_of(diagnosis, candidate.table), target=magnitude)
            result = mf.solve(mf.over_profile(diagnosis.model, profile), solver, {})
            if int(result.attrs.get("interrupted", 0)):  # a run cut short verifies nothing: not kept
                raise KeyboardInterrupt
            numbers = {n.name: n.value for n in mf.key_numbers(result)}
            candidate.verified = {key: numbers.get(key) for key in ("crack_width", "damage_category",
                                                                    "minimum_reaction", "dead_reaction",
                                                                    "final_settlement")}
    except KeyboardInterrupt:
        diagnosis.verify_interrupted = True
        return
    progress(1.0, "verify: done")
