"""The Jointed Masonry Model in 2D (paper eqs. 12-14): elastic predictor, exact return, consistent tangent.

Stresses are vectors ``[sxx, syy, sxy]`` (tension positive), strains ``[exx, eyy, gxy]``
(engineering shear). Two joint planes: the *bed* plane (normal y: sigma_n = syy,
tau = sxy) and the *head* plane (normal x: sigma_n = sxx, tau = sxy). Eq. 14 raises
the head-plane strength by the interlocking term: with beta = tan(phi_bed) b / (2a),

    head cut-off:  sxx + beta syy <= sigma_t0,head + c0,bed beta / tan(phi_bed)
    head Coulomb:  |sxy| + (sxx + beta syy) tan(phi_head) <= c0,head + c0,bed beta tan(phi_head)/tan(phi_bed)

so every face of the strength domain is linear in the stress: the domain is the
polyhedron ``A s <= b`` (at most six faces: +tau, -tau and cut-off per plane). A
cut-off at or beyond its plane's Coulomb apex (sigma_t >= c cot(phi), e.g. the paper's
c = sigma_t = 0) can never bind and is dropped, so no degenerate apex remains.

The return is the closest point in the energy norm (associated flow) or the
projection along the plastic-potential gradients ``G`` (dilatancy psi != phi): an
active-set choice among all subsets of at most three independent faces, each solved in
closed form and checked for KKT (multipliers >= 0, every face satisfied), vectorised
over all quadrature points. Faces are linear, so the tangent of a fixed active set is
exact: ``C = D - D G_S^T (A_S D G_S^T)^-1 A_S D``; on an edge (two faces) it has rank 1,
at a vertex (three faces) it is zero. ``vertex_stiffness * D`` can be added there (the
solver adds its own, see newton.py); the stress update is untouched, so the converged
solution does not depend on it, only the Newton path does.
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np

import masonryfw as mf

#: face names, in the order of the rows of ``A``; cut-offs only when they can bind
FACES = ("bed+", "bed-", "head+", "head-", "bed_cutoff", "head_cutoff")
BED_FACES = (0, 1, 4)
HEAD_FACES = (2, 3, 5)
FAILURE = {"elastic": 0, "tensile": 1, "shear": 2, "tensile_shear": 3}


@dataclass(frozen=True)
class JointStrength:
    """Strength of the two joint planes (paper eqs. 12-14); stresses in any consistent unit."""

    friction_bed: float  # tan(phi_2)
    friction_head: float  # tan(phi_1)
    cohesion_bed: float = 0.0
    cohesion_head: float = 0.0
    tensile_bed: float = 0.0
    tensile_head: float = 0.0
    beta: float = 0.0
    dilatancy_bed: float | None = None  # tan(psi_2); None = associated
    dilatancy_head: float | None = None

    def __post_init__(self):
        for name in ("friction_bed", "friction_head"):
            if not getattr(self, name) > 0:
                raise mf.ModelError(f"JMM strength: {name} must be > 0, got {getattr(self, name)}")
        for name in ("cohesion_bed", "cohesion_head", "tensile_bed", "tensile_head", "beta"):
            if getattr(self, name) < 0:
                raise mf.ModelError(f"JMM strength: {name} must be >= 0, got {getattr(self, name)}")

    def faces(self):
        """``(A, b, G, names)``: faces ``A s <= b`` and flow gradients ``G`` (rows), binding cut-offs only."""
        tb, th, beta = self.friction_bed, self.friction_head, self.beta
        pb = tb if self.dilatancy_bed is None else self.dilatancy_bed
        ph = th if self.dilatancy_head is None else self.dilatancy_head
        head_shift = self.cohesion_bed * beta / tb  # eq. 14: c0,2 beta / tan(phi_2)
        c_head = self.cohesion_head + head_shift * th
        t_head = self.tensile_head + head_shift
        rows = [
            ([0.0, tb, 1.0], self.cohesion_bed, [0.0, pb, 1.0]),
            ([0.0, tb, -1.0], self.cohesion_bed, [0.0, pb, -1.0]),
            ([th, beta * th, 1.0], c_head, [ph, beta * ph, 1.0]),
            ([th, beta * th, -1.0], c_head, [ph, beta * ph, -1.0]),
        ]
        names = list(FACES[:4])
        if self.tensile_bed < self.cohesion_bed / tb:  # cut-off below the Coulomb apex: it can bind
            rows.append(([0.0, 1.0, 0.0], self.tensile_bed, [0.0, 1.0, 0.0]))
            names.append(FACES[4])
        if t_head < c_head / th:
            rows.append(([1.0, beta, 0.0], t_head, [1.0, beta, 0.0]))
            names.append(FACES[5])
        A, b, G = (np.array(v, dtype=float) for v in zip(*rows))
        return A, b, G, tuple(names)

    def scaled(self, stress_scale: float) -> JointStrength:
        """The same strength with cohesions and tensile strengths divided by ``stress_scale``."""
        return JointStrength(
            self.friction_bed, self.friction_head, self.cohesion_bed / stress_scale,
            self.cohesion_head / stress_scale, self.tensile_bed / stress_scale,
            self.tensile_head / stress_scale, self.beta, self.dilatancy_bed, self.dilatancy_head,
        )


def elastic_matrix(young: float, poisson: float, hypothesis: str = "plane_stress") -> np.ndarray:
    """3 x 3 isotropic elasticity for ``[sxx, syy, sxy]`` against ``[exx, eyy, gxy]``."""
    if not young > 0 or not -1.0 < poisson < 0.5:
        raise mf.ModelError(f"elastic constants: need E > 0 and -1 < nu < 0.5, got E={young}, nu={poisson}")
    if hypothesis == "plane_stress":
        k = young / (1.0 - poisson**2)
        return k * np.array([[1.0, poisson, 0.0], [poisson, 1.0, 0.0], [0.0, 0.0, (1.0 - poisson) / 2.0]])
    if hypothesis == "plane_strain":
        lam = young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson))
        mu = young / (2.0 * (1.0 + poisson))
        return np.array([[lam + 2 * mu, lam, 0.0], [lam, lam + 2 * mu, 0.0], [0.0, 0.0, mu]])
    raise mf.ModelError(f"hypothesis {hypothesis!r}: use 'plane_stress' or 'plane_strain'")


@dataclass(frozen=True)
class ActiveSet:
    """One candidate active set, precomputed: ``stress = trial - P (A_S trial - b_S)``."""

    faces: tuple[int, ...]
    M: np.ndarray  # (k, k) = (A_S D G_S^T)^-1
    P: np.ndarray  # (3, k) = D G_S^T M
    shift: np.ndarray  # (faces, k) = A P: change of every yield value per unit excess
    tangent: np.ndarray  # (3, 3)


class ReturnMap:
    """Exact return onto the JMM polyhedron for one elastic matrix ``D``, vectorised over points."""

    def __init__(self, strength: JointStrength, D: np.ndarray, vertex_stiffness: float = 0.0):
        self.D = np.asarray(D, dtype=float)
        self.A, self.b, self.G, self.names = strength.faces()
        self.vertex_stiffness = vertex_stiffness
        self.sets = self._candidate_sets()

    def _candidate_sets(self) -> list[ActiveSet]:
        D, A, b, G = self.D, self.A, self.b, self.G
        sets = []
        for size in (1, 2, 3):
            for faces in combinations(range(len(b)), size):
                S = list(faces)
                H = A[S] @ D @ G[S].T
                if np.linalg.matrix_rank(A[S]) < size or abs(np.linalg.det(H)) < 1e-12 * np.linalg.norm(H) ** size:
                    continue
                M = np.linalg.inv(H)
                P = D @ G[S].T @ M
                tangent = D - P @ A[S] @ D
                if size >= 2:  # edge (rank 1) or vertex (zero): keep a small elastic part
                    tangent = tangent + self.vertex_stiffness * D
                sets.append(ActiveSet(faces, M, P, np.ascontiguousarray(A @ P), tangent))
        return sets

    def __call__(self, trial: np.ndarray, tol: float = 1e-10, bounds: np.ndarray | None = None):
        """Return ``(stress, tangent, active, multipliers)`` for trial stresses ``(n, 3)``.

        ``bounds``: ``(faces, n)`` right-hand sides per point replacing ``b`` (a face that a point
        does not have gets a bound it never reaches); the candidate sets do not depend on them.

        ``active`` is a boolean ``(n, faces)`` (faces with a positive multiplier),
        ``tangent`` is ``(n, 3, 3)``; elastic points get ``D``. Every candidate set is
        evaluated on the yield values only (``A s - b`` is linear in the stress), and each
        point takes the first set, smallest first, whose multipliers are >= 0 and whose
        stress satisfies every face; if round-off leaves none, the least violated one.
        """
        trial = np.asarray(trial, dtype=float)
        n, nf = trial.shape[0], len(self.b)
        values = self.A @ trial.T - (self.b[:, None] if bounds is None else bounds)  # (faces, n): face-major
        scale = tol * (1.0 + np.abs(trial).max(axis=1))
        stress = trial.copy()
        tangent = np.broadcast_to(self.D, (n, 3, 3)).copy()
        active = np.zeros((n, nf), dtype=bool)
        multipliers = np.zeros((n, nf))
        todo = np.nonzero((values > scale).any(axis=0))[0]
        if todo.size == 0:
            return stress, tangent, active, multipliers
        f, allowed = values[:, todo], 10.0 * scale[todo]
        violation = np.empty((len(self.sets), todo.size))
        for k, s in enumerate(self.sets):
            excess = f[list(s.faces)]
            lam = s.M @ excess
            after = f - s.shift @ excess
            violation[k] = np.maximum(after.max(axis=0), (-lam).max(axis=0))
        ok = violation <= allowed
        chosen = np.where(ok.any(axis=0), ok.argmax(axis=0), violation.argmin(axis=0))
        for k in np.unique(chosen):
            s, rows = self.sets[k], todo[chosen == k]
            faces = list(s.faces)
            excess = values[np.ix_(faces, rows)]
            lam = (s.M @ excess).T
            stress[rows] = trial[rows] - (s.P @ excess).T
            tangent[rows] = s.tangent
            multipliers[np.ix_(rows, faces)] = np.maximum(lam, 0.0)
            active[np.ix_(rows, faces)] = lam > 0.0
        return stress, tangent, active, multipliers

    def failure_mode(self, active: np.ndarray) -> np.ndarray:
        """:func:`failure_mode` of this domain's faces."""
        return failure_mode(active, self.names)


def failure_mode(active: np.ndarray, names: tuple[str, ...]) -> np.ndarray:
    """int8 flags per point: 0 elastic, 1 tensile, 2 shear, 3 tensile_shear, from the active faces ``names``.

    On a plane, an active cut-off or both Coulomb faces active (the apex: the joint
    opens) is tensile; one Coulomb face alone is shear. A point with a tensile plane
    and a shear plane is tensile_shear.
    """
    index = {name: i for i, name in enumerate(names)}
    tensile = np.zeros(active.shape[0], dtype=bool)
    shear = np.zeros(active.shape[0], dtype=bool)
    for plane in ("bed", "head"):
        plus, minus = active[:, index[f"{plane}+"]], active[:, index[f"{plane}-"]]
        cutoff = active[:, index[f"{plane}_cutoff"]] if f"{plane}_cutoff" in index else np.zeros_like(plus)
        opening = cutoff | (plus & minus)
        tensile |= opening
        shear |= (plus ^ minus) & ~opening
    return (tensile * FAILURE["tensile"] + shear * FAILURE["shear"]).astype(np.int8)
