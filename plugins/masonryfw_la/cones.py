"""The cones of the interior point (:mod:`.ipm`): the non-negative orthant (an LP) and 3-dimensional second-order
cones (Coulomb's).

The interior point works in the scaled space of Nesterov and Todd: for ``s`` and ``y`` inside the cone a scaling
``W`` with ``W^-1 s = W y = lambda``. The Newton step's complementarity ``lambda o (W^-1 ds + W dy) = rc``
(``o`` the cone's Jordan product) eliminates ``ds`` and ``dy``, and the normal matrix is ``G^T W^-2 G``: for
the orthant ``W^-2 = diag(y / s)``, for second-order cones of dimension ``k`` a symmetric ``k x k`` block per
cone, so the normal matrix keeps the sparsity of ``G^T G`` over each cone's rows (its ``k`` rows are one contact
point's: they touch the same blocks). Formulas: Vandenberghe, "The CVXOPT linear and quadratic cone program
solvers" (2010), sections 3-4.

The second-order cones' scaled products, Jordan products and steps are compiled loops over the cones
(:mod:`.lorentz_kernels`, numba, imported by 3D solves only: an LP does not pay for numba's import); the rest is
vectorised over the cones, column by column (numpy's einsum and batched matmul are several times slower on 3 x 3
blocks). Vectors are stacked cone after cone (``k`` entries each).
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

HALF_ROOT = np.sqrt(0.5)


class OrthantScaling(NamedTuple):
    """``W = diag(sqrt(s / y))``: ``lambda = sqrt(s y)``; with ``weight`` (a regularised programme) the normal
    weight is ``y / (s + w y)``."""

    s: np.ndarray
    y: np.ndarray
    weight: np.ndarray

    @property
    def normal_weights(self) -> np.ndarray:
        """The weights the normal matrix is formed with: ``W^-2`` (one per row)."""
        return self.y / (self.s + self.weight * self.y)

    def times_normal_weights(self, v: np.ndarray) -> np.ndarray:
        return self.normal_weights * v

    def times_normal_weights_inverse(self, v: np.ndarray) -> np.ndarray:
        return (self.s / self.y + self.weight) * v

    def target_rhs(self, rc: np.ndarray) -> np.ndarray:
        """``W (lambda \\ rc)``: the primal rows' share of the complementarity ``rc`` (``rc / y``)."""
        return rc / self.y

    def scaled_product(self, ds: np.ndarray, dy: np.ndarray) -> np.ndarray:
        """``(W^-1 ds) o (W dy)``: Mehrotra's second-order term."""
        return ds * dy

    def lam_squared(self) -> np.ndarray:
        """``lambda o lambda = s y``."""
        return self.s * self.y

    def primal_shift(self, dy: np.ndarray) -> np.ndarray:
        """``ds - G dx - rp``: ``w dy`` (a regularised programme's ``y`` is in its primal rows)."""
        return self.weight * dy


class Orthant:
    """The non-negative orthant of ``m`` rows (an LP)."""

    size = 1

    def __init__(self, rows: int):
        self.degree = rows

    @staticmethod
    def identity(v: np.ndarray) -> np.ndarray:
        return np.ones_like(v)

    @staticmethod
    def smallest_eigenvalue(v: np.ndarray) -> float:
        return float(v.min(initial=np.inf))

    @staticmethod
    def identity_weight(v: np.ndarray) -> float:
        """``e . v``."""
        return float(v.sum())

    @staticmethod
    def max_step(v: np.ndarray, dv: np.ndarray) -> float:
        """Largest ``t <= 1`` with ``v + t dv >= 0`` (``v > 0``)."""
        fastest = (dv / v).min(initial=0.0)
        return 1.0 if fastest >= -1.0 else -1.0 / fastest

    @staticmethod
    def scaling(s: np.ndarray, y: np.ndarray, weight: np.ndarray) -> OrthantScaling:
        return OrthantScaling(s, y, weight)

    @staticmethod
    def trial_product(scaling, s, ds, y, dy, primal: float, dual: float) -> np.ndarray:
        """The complementarity products after steps ``primal`` and ``dual``."""
        return (s + primal * ds) * (y + dual * dy)

    @staticmethod
    def centring(product: np.ndarray, target: float) -> np.ndarray:
        """Gondzio's correction: what brings each product into ``[0.1, 10] x target``."""
        return gondzio(product, target)


def gondzio(values: np.ndarray, target: float) -> np.ndarray:
    """What moves each of ``values`` into ``[0.1, 10] x target`` (down by at most ``10 x target``)."""
    return np.clip(0.1 * target - values, 0.0, None) + np.clip(10.0 * target - values, -10.0 * target, 0.0)


class LorentzScaling(NamedTuple):
    """The Nesterov-Todd scaling of 3-dimensional second-order cones, ``W = eta (2 v v^T - J)`` per cone (``J =
    diag(1, -1, -1)``, ``v^T J v = 1``), kept as its eigen-decomposition ``W^-1 = U diag(sigma) U^T``: the
    eigenvectors ``u0, u1 = (1, -+d) / sqrt(2)`` and ``u2 = (0, d')`` (``d`` the unit direction of ``v1``, ``d'``
    it turned by 90 degrees) with ``sigma = (v0 + |v1|)^2 / eta``, ``(v0 - |v1|)^2 / eta`` (``v0 - |v1| = 1 /
    (v0 + |v1|)``, no cancellation) and ``1 / eta``. The normal matrix is formed from the rows ``diag(sigma) U^T
    G`` of each cone, a sum of positive rank-one terms as an LP's ``d g g^T``: the entries of ``W^-2`` itself span
    ``sigma``'s range squared and, formed first, would lose its small directions.

    A regularised programme (``weight`` ``w`` on each cone's first component, ``s = G x + w y0 e0``) has the normal
    weights ``(W^2 + w e0 e0^T)^-1``, ``W^-2`` less a rank-one term (Sherman and Morrison), and its normal rows
    are ``diag(sigma) U^T`` times ``I - gamma z z^T``, ``z`` the unit first column of those rows and ``(1 -
    gamma)^2 = 1 / (1 + w h)``, ``h = (W^-2)_00``: still rows, never the difference of two matrices."""

    direction: np.ndarray  # (cone, 2) d
    sigma: np.ndarray  # (cone, 3) eigenvalues of W^-1
    lam: np.ndarray  # (cone, 3) W y = W^-1 s
    weight: np.ndarray | None = None  # (cone,) a regularised programme's weight on each cone's first component

    def times(self, power: int, v: np.ndarray) -> np.ndarray:
        """``W^-power v`` (``power`` = 1, -1, 2, -2): ``U diag(sigma^power) U^T v``."""
        from . import lorentz_kernels

        with np.errstate(divide="ignore"):  # a cone on its boundary: inf, and the iteration's error says so
            powered = self.sigma ** float(power)
        return lorentz_kernels.scaled(self.direction, powered, np.ascontiguousarray(v, dtype=float))

    @property
    def normal_rows(self) -> np.ndarray:
        """(cone, 3, 3): ``diag(sigma) U^T``, whose rows times ``G``'s are the normal matrix's (``M = sum r r^T``)."""
        d0, d1 = self.direction[:, 0], self.direction[:, 1]
        zero = np.zeros_like(d0)
        rows = np.stack([np.c_[np.full_like(d0, HALF_ROOT), -HALF_ROOT * d0, -HALF_ROOT * d1],
                         np.c_[np.full_like(d0, HALF_ROOT), HALF_ROOT * d0, HALF_ROOT * d1],
                         np.c_[zero, -d1, d0]], axis=1)
        rows = self.sigma[:, :, None] * rows
        if self.weight is None:
            return rows
        first = rows[:, :, 0]
        h = dots(first, first)
        gamma = 1.0 - 1.0 / np.sqrt(1.0 + self.weight * h)
        z = first / np.sqrt(h)[:, None]
        return rows - (gamma[:, None] * z)[:, :, None] * np.einsum("ck,ckj->cj", z, rows)[:, None, :]

    def times_normal_weights(self, v: np.ndarray) -> np.ndarray:
        """``(W^2 + w e0 e0^T)^-1 v``."""
        out = self.times(2, v)
        if self.weight is None:
            return out
        out = out.reshape(-1, 3)
        u = self.times(2, first_unit(out.shape[0])).reshape(-1, 3)  # W^-2 e0
        out -= (self.weight * out[:, 0] / (1.0 + self.weight * u[:, 0]))[:, None] * u
        return out.ravel()

    def times_normal_weights_inverse(self, v: np.ndarray) -> np.ndarray:
        """``(W^2 + w e0 e0^T) v``."""
        out = self.times(-2, v)
        if self.weight is not None:
            out = out.reshape(-1, 3)
            out[:, 0] += self.weight * np.asarray(v).reshape(-1, 3)[:, 0]
            out = out.ravel()
        return out

    def target_rhs(self, rc: np.ndarray) -> np.ndarray:
        """``W (lambda \\ rc)``."""
        from . import lorentz_kernels

        return self.times(-1, lorentz_kernels.arrow_solve(self.lam.ravel(), np.ascontiguousarray(rc)))

    def scaled_product(self, ds: np.ndarray, dy: np.ndarray) -> np.ndarray:
        """``(W^-1 ds) o (W dy)``."""
        from . import lorentz_kernels

        return lorentz_kernels.jordan(self.times(1, ds), self.times(-1, dy))

    def lam_squared(self) -> np.ndarray:
        """``lambda o lambda``."""
        from . import lorentz_kernels

        lam = self.lam.ravel()
        return lorentz_kernels.jordan(lam, lam)

    def primal_shift(self, dy: np.ndarray) -> np.ndarray | float:
        """``ds - G dx - rp``: ``w dy0 e0`` (a regularised programme's ``y0`` is in its primal rows), else nothing."""
        if self.weight is None:
            return 0.0
        out = np.zeros((self.weight.size, 3))
        out[:, 0] = self.weight * np.asarray(dy).reshape(-1, 3)[:, 0]
        return out.ravel()


def first_unit(count: int) -> np.ndarray:
    """``e0`` of ``count`` cones of three, stacked."""
    e = np.zeros((count, 3))
    e[:, 0] = 1.0
    return e.ravel()


def dots(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``u_c . v_c`` per cone (rows of ``u`` and ``v``), column by column."""
    out = u[:, 0] * v[:, 0]
    for a in range(1, u.shape[1]):
        out += u[:, a] * v[:, a]
    return out


def lorentz_norm2(v: np.ndarray) -> np.ndarray:
    """``v^T J v = v0^2 - |v1|^2`` per cone, as ``(v0 - |v1|) (v0 + |v1|)`` (no cancellation near the boundary)."""
    tail = np.sqrt(dots(v[:, 1:], v[:, 1:]))
    return (v[:, 0] - tail) * (v[:, 0] + tail)


class SecondOrderCones:
    """``count`` second-order cones of dimension 3 (Coulomb's: ``v0 >= |(v1, v2)|``)."""

    size = 3

    def __init__(self, count: int):
        self.degree = count

    def identity(self, v: np.ndarray) -> np.ndarray:
        return first_unit(v.size // self.size)

    @staticmethod
    def product(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        from . import lorentz_kernels

        return lorentz_kernels.jordan(np.ascontiguousarray(u, dtype=float), np.ascontiguousarray(v, dtype=float))

    def trial_product(self, scaling: LorentzScaling, s, ds, y, dy, primal: float, dual: float) -> np.ndarray:
        """The scaled complementarity ``(lambda + primal W^-1 ds) o (lambda + dual W dy)`` after the steps."""
        lam = scaling.lam.ravel()
        return self.product(lam + primal * scaling.times(1, ds), lam + dual * scaling.times(-1, dy))

    def centring(self, product: np.ndarray, target: float) -> np.ndarray:
        """Gondzio's correction on each cone's spectral values ``p0 -+ |p1|`` (frames ``(1, -+p1 / |p1|) / 2``):
        what brings them into ``[0.1, 10] x target``."""
        p = product.reshape(-1, self.size)
        norm = np.sqrt(dots(p[:, 1:], p[:, 1:]))
        low, high = p[:, 0] - norm, p[:, 0] + norm
        shift_low, shift_high = gondzio(low, target), gondzio(high, target)
        unit = p[:, 1:] / np.where(norm > 0.0, norm, 1.0)[:, None]
        return np.c_[0.5 * (shift_low + shift_high), 0.5 * (shift_high - shift_low)[:, None] * unit].ravel()

    def smallest_eigenvalue(self, v: np.ndarray) -> float:
        v = v.reshape(-1, self.size)
        return float((v[:, 0] - np.sqrt(dots(v[:, 1:], v[:, 1:]))).min(initial=np.inf))

    def identity_weight(self, v: np.ndarray) -> float:
        return float(v.reshape(-1, self.size)[:, 0].sum())

    @staticmethod
    def max_step(v: np.ndarray, dv: np.ndarray) -> float:
        """Largest ``t <= 1`` keeping ``v + t dv`` in every cone (``v`` inside): the smallest positive root of
        ``(v0 + t d0)^2 - |v1 + t d1|^2``, ``a t^2 + 2 b t + c`` with ``c > 0`` (a linear one, ``a = 0``, at
        ``-c / 2b``, which ``c / q`` gives), and the first component kept positive: through the apex ``f`` is
        positive again, and a cone whose tail is zero (the orthant written as a cone) has a double root that rounding
        can make complex."""
        from . import lorentz_kernels

        return float(lorentz_kernels.max_step(np.ascontiguousarray(v, dtype=float),
                                              np.ascontiguousarray(dv, dtype=float)))

    def scaling(self, s: np.ndarray, y: np.ndarray, weight: np.ndarray | None = None) -> LorentzScaling:
        """The scaling at ``(s, y)``; ``weight`` (one per row, zero but on first components) a regularised
        programme's."""
        first_weight = None if weight is None or not np.any(weight) else np.asarray(weight).reshape(-1, 3)[:, 0]
        s, y = s.reshape(-1, 3), y.reshape(-1, 3)
        # an iterate rounded onto a cone's boundary gives nan here, and the next iteration's error says so
        with np.errstate(invalid="ignore", divide="ignore"):
            ns, ny = np.sqrt(lorentz_norm2(s)), np.sqrt(lorentz_norm2(y))
            sbar, ybar = s / ns[:, None], y / ny[:, None]
            gamma = np.sqrt(0.5 * (1.0 + dots(sbar, ybar)))
            wbar = (sbar + ybar * np.array([1.0, -1.0, -1.0])) / (2.0 * gamma[:, None])  # W^2 = eta^2 (2 wbar wbar^T - J)
            eta = np.sqrt(ns / ny)
        v = wbar + np.array([1.0, 0.0, 0.0])
        v /= np.sqrt(2.0 * v[:, :1])  # (wbar + e) / sqrt(2 (wbar0 + 1))
        tail = np.sqrt(dots(v[:, 1:], v[:, 1:]))
        direction = np.where(tail[:, None] > 0.0, v[:, 1:] / np.where(tail > 0.0, tail, 1.0)[:, None],
                             np.array([1.0, 0.0]))  # v1 / |v1|, any unit vector when v1 = 0
        big = (v[:, 0] + tail) ** 2
        sigma = np.c_[big, 1.0 / big, np.ones_like(big)] / eta[:, None]
        scaling = LorentzScaling(direction, sigma, np.zeros_like(s))
        return scaling._replace(lam=scaling.times(-1, y.ravel()).reshape(-1, 3), weight=first_weight)
