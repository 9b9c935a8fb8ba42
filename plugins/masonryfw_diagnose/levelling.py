"""A levelling as evidence: each candidate's motion fitted to the course, the families compared by likelihood, and
a free ground profile for what no family describes.

A levelling measures the wall's own motion along a course that was laid level (``x, y, dy``, dy negative down).
Under a candidate the course can move two ways, and a real wall lies between them: as the candidate's
mechanism moves it (la's collapse mechanism per unit settlement, ``p_m``: a part that translates, one that
rotates, a wall that bridges), or following its ground (``p_g = -rate(x)``, the profile under each point: a
wall soft enough to settle with the ground). The fit is

    dy = a + t_m p_m + t_g p_g,    t_m, t_g >= 0  (a: the levelling's datum)

by bounded least squares; the **magnitude** is ``t_m + t_g`` (both per unit settlement), its standard error
that of the noise (``sigma`` over the spread of the fitted shape) and a model error of :data:`MODEL_ERROR` of
itself. The noise ``sigma`` is given (``--levelling-sigma``) or read from the data without a model
(:func:`noise`: the median absolute deviation of the course's second differences, which a smooth motion
leaves near zero and a jump or two do not move).

**Comparing candidates and families.** With Gaussian noise the log-likelihood of a fit is ``-SS / (2 s^2)``,
``s^2`` the larger of ``sigma^2`` and the best candidate's residual variance (the model error, when no candidate
fits to the noise). A family's evidence is the mean likelihood of its candidates (the grid of its parameters
with a uniform prior: a family that fits only at a few places pays for the rest), and the families'
probabilities are their evidences normalised. The **levelling score** of a candidate, what the ranking
multiplies with the crack score, is ``(SS_best + n sigma^2) / (SS + n sigma^2)``: 1 for the best fit, a half
for one whose residual is twice the best's plus the noise. (``R^2 = 1 - SS / SS_tot`` does not rank: a course
that moved millimetres is fitted with R^2 > 0.95 by every shape that settles the right end.)

**The free profile.** The ground segments' settlements ``s_j >= 0`` (each translating as one) fitted to the
levelling as if the course followed it, with a sparsity prior on its changes, the total
variation ``lambda sum |s_j+1 - s_j|`` (a step stays a step, where a smoothness prior rings about it), its
weight the largest whose fit leaves a residual no larger than the noise (Morozov's discrepancy principle): a
cause outside the three families (two troughs, a soft spot and a tilt) is still described.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: The relative error of a magnitude beyond the levelling's noise: a wall neither moves exactly as its mechanism
#: nor follows its ground. On the held-out surveys' tuning half (docs/diagnose.md) the magnitude of the plausible
#: candidate fitting the levelling best was off the truth by a median of 7.7 % (|log ratio| 0.077, a normal's
#: 0.67 sigma: sigma 0.115).
MODEL_ERROR = 0.115
#: The total-variation weights tried, relative to the data's scale.
LAMBDAS = tuple(10.0 ** np.arange(-6.0, 3.5, 0.5))


def noise(x: np.ndarray, dy: np.ndarray) -> float:
    """The levelling's noise read from the data alone: ``1.4826 MAD(D2 dy) / sqrt(6)`` over the points in order of
    ``x`` (a normal noise's standard deviation; the second differences of a straight course are its noise's, with
    a variance six times its own), floored at a millionth of the course's range."""
    if dy.size < 4:
        return 1e-6 * float(np.ptp(dy)) + 1e-12
    second = np.diff(dy[np.argsort(x)], n=2)
    mad = float(np.median(np.abs(second - np.median(second))))
    return max(1.4826 * mad / math.sqrt(6.0), 1e-6 * float(np.ptp(dy)), 1e-12)


@dataclass(frozen=True)
class Fit:
    """A candidate's fit to the levelling (module docstring)."""

    magnitude: float  # t_m + t_g [m]
    spread: float  # its standard error [m]
    residual: float  # SS [m^2]
    share_ground: float  # t_g / (t_m + t_g): 0 moving as the mechanism, 1 following the ground
    fitted: np.ndarray  # the fitted dy at the levelled points [m]


def fit(dy: np.ndarray, mechanism: np.ndarray, ground: np.ndarray, sigma: float) -> Fit:
    """The bounded least-squares fit of ``dy = a + t_m mechanism + t_g ground`` (module docstring)."""
    from scipy.optimize import lsq_linear

    scale = max(float(np.abs(dy - dy.mean()).max()), 1e-12)
    design = np.c_[np.ones_like(dy), mechanism, ground]
    norms = np.maximum(np.abs(design).max(axis=0), 1e-300)
    solution = lsq_linear(design / norms, dy / scale, bounds=([-np.inf, 0.0, 0.0], [np.inf, np.inf, np.inf]),
                          method="bvls")
    datum, t_m, t_g = solution.x * scale / norms
    shape = t_m * mechanism + t_g * ground
    residual = float(((dy - datum - shape) ** 2).sum())
    magnitude = t_m + t_g
    centred = shape / magnitude - (shape / magnitude).mean() if magnitude > 0 else np.zeros_like(dy)
    spread_of_shape = math.sqrt(float((centred**2).sum()))
    noise = max(sigma, math.sqrt(residual / max(dy.size - 3, 1)))
    spread = math.hypot(noise / spread_of_shape, MODEL_ERROR * magnitude) if spread_of_shape > 0 else math.inf
    return Fit(float(magnitude), float(spread), residual, float(t_g / magnitude) if magnitude > 0 else 0.0,
               datum + shape)


def scores(fits: list[Fit], sigma: float, points: int) -> np.ndarray:
    """Every candidate's levelling score ``(SS_best + n sigma^2) / (SS + n sigma^2)`` (module docstring)."""
    residual = np.array([f.residual for f in fits])
    noise = points * sigma**2 + 1e-30
    return (residual.min() + noise) / (residual + noise)


def family_probabilities(fits: list[Fit], families: list[str], sigma: float, points: int) -> dict[str, float]:
    """Each family's probability from its evidence, the mean likelihood of its candidates (module docstring)."""
    residual = np.array([f.residual for f in fits])
    variance = max(sigma**2, residual.min() / max(points - 3, 1), 1e-30)
    log_likelihood = -(residual - residual.min()) / (2.0 * variance)
    evidence = {}
    for family in dict.fromkeys(families):
        mine = log_likelihood[[f == family for f in families]]
        evidence[family] = float(np.log(np.mean(np.exp(mine - mine.max()))) + mine.max())
    top = max(evidence.values())
    weights = {f: math.exp(e - top) for f, e in evidence.items()}
    total = sum(weights.values())
    return {f: w / total for f, w in weights.items()}


@dataclass(frozen=True)
class FreeProfile:
    """The ground's settlement at the segment ends, fitted freely (module docstring)."""

    x: np.ndarray  # the segments' middles [m]
    settlement: np.ndarray  # each segment's [m], at least 0, the least settling at 0
    sigma: float  # the residual's standard deviation [m]
    smoothness: float  # the weight of the total-variation prior (relative)

    @property
    def magnitude(self) -> float:
        return float(self.settlement.max())

    def table(self) -> dict:
        """The free profile as a ``[settlement]`` table (``profile = "table"``: rates over the largest)."""
        rate = self.settlement / self.magnitude if self.magnitude > 0 else self.settlement
        return {"profile": "table", "points": [[round(float(x), 6), round(float(r), 4)] for x, r in zip(self.x, rate)]}


def segment_basis(x: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """``(len(x), len(nodes) - 1)``: 1 where a point lies over a segment (a ground segment translates as one)."""
    segment = np.clip(np.searchsorted(nodes, x, side="right") - 1, 0, nodes.size - 2)
    basis = np.zeros((x.size, nodes.size - 1))
    basis[np.arange(x.size), segment] = 1.0
    return basis


def free_profile(x: np.ndarray, dy: np.ndarray, nodes: np.ndarray, sigma: float) -> FreeProfile:
    """The free ground profile under levelled points ``(x, dy)`` over ground ``nodes``, the levelling's noise
    ``sigma`` (module docstring): the largest total-variation weight whose fit leaves the noise."""
    scale = max(float(np.abs(dy - dy.mean()).max()), 1e-12)
    basis = -segment_basis(x, nodes)  # dy = a - s_j, j the segment under the point
    design = np.c_[np.ones_like(dy), basis]
    chosen = None
    for weight in sorted(LAMBDAS, reverse=True):
        solution = _total_variation_fit(design, dy / scale, weight)
        residual = dy / scale - design @ solution
        chosen = (weight, solution)
        if float(residual @ residual) <= dy.size * (sigma / scale) ** 2:
            break
    assert chosen is not None
    weight, solution = chosen
    settlement = solution[1:] * scale
    residual = dy - design @ solution * scale
    jumps = int((np.abs(np.diff(settlement)) > 1e-3 * max(float(np.ptp(settlement)), 1e-300)).sum())
    return FreeProfile(0.5 * (nodes[:-1] + nodes[1:]), settlement - settlement.min(),
                       math.sqrt(float((residual**2).sum()) / max(dy.size - 1 - jumps, 1)), weight)


def _total_variation_fit(design: np.ndarray, rhs: np.ndarray, weight: float, iterations: int = 30) -> np.ndarray:
    """``(a, s)`` minimising ``|design (a, s) - rhs|^2 + weight sum |s_j+1 - s_j|``, ``s >= 0``, by iteratively
    reweighted least squares (each step a bounded least-squares problem); a small ridge picks the least
    settlement (the datum and a uniform ``s`` are one)."""
    from scipy.optimize import lsq_linear

    n = design.shape[1] - 1
    first = np.c_[np.zeros((max(n - 1, 0), 1)), np.diff(np.eye(n), axis=0)]
    ridge = np.c_[np.zeros((n, 1)), 1e-4 * np.eye(n)]
    bounds = (np.r_[-np.inf, np.zeros(n)], np.full(n + 1, np.inf))
    solution = np.zeros(n + 1)
    for _ in range(iterations):
        slopes = np.abs(first @ solution)
        reweighted = first * np.sqrt(weight / (2.0 * np.maximum(slopes, 1e-6)))[:, None]
        rows = np.r_[design, reweighted, ridge]
        updated = lsq_linear(rows, np.r_[rhs, np.zeros(rows.shape[0] - rhs.size)], bounds=bounds, method="bvls").x
        if np.abs(updated - solution).max() <= 1e-9:
            return updated
        solution = updated
    return solution
