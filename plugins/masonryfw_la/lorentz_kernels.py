"""The per-cone arithmetic of 3-dimensional second-order cones that the interior point runs several times an
iteration, compiled (numba): one pass over the cones without NumPy's temporaries. At 9,663 blocks (114,280 cones)
these took 3.4 s of a 15 s solve as NumPy column operations (docs/benchmarks.md, "la in 3D at scale").

Vectors are stacked cone after cone, three entries each; the formulas are :mod:`.cones`'.
"""
from __future__ import annotations

import numpy as np
from numba import njit

HALF_ROOT = np.sqrt(0.5)


@njit(cache=True, error_model="numpy")
def scaled(direction, powered, v):
    """``W^-power v`` for the scalings ``W^-1 = U diag(sigma) U^T`` (:class:`.cones.LorentzScaling`), given
    ``powered = sigma^power``."""
    n = powered.shape[0]
    out = np.empty(3 * n)
    for c in range(n):
        d0, d1 = direction[c, 0], direction[c, 1]
        v0, v1, v2 = v[3 * c], v[3 * c + 1], v[3 * c + 2]
        along = d0 * v1 + d1 * v2
        c0 = HALF_ROOT * (v0 - along) * powered[c, 0]
        c1 = HALF_ROOT * (v0 + along) * powered[c, 1]
        c2 = (d0 * v2 - d1 * v1) * powered[c, 2]
        half = HALF_ROOT * (c1 - c0)
        out[3 * c] = HALF_ROOT * (c0 + c1)
        out[3 * c + 1] = d0 * half - d1 * c2
        out[3 * c + 2] = d1 * half + d0 * c2
    return out


@njit(cache=True, error_model="numpy")
def jordan(u, v):
    """``u o v = (u . v, u0 v1 + v0 u1)`` per cone, stacked."""
    n = u.size // 3
    out = np.empty(3 * n)
    for c in range(n):
        u0, u1, u2 = u[3 * c], u[3 * c + 1], u[3 * c + 2]
        v0, v1, v2 = v[3 * c], v[3 * c + 1], v[3 * c + 2]
        out[3 * c] = u0 * v0 + u1 * v1 + u2 * v2
        out[3 * c + 1] = u0 * v1 + v0 * u1
        out[3 * c + 2] = u0 * v2 + v0 * u2
    return out


@njit(cache=True, error_model="numpy")
def arrow_solve(lam, r):
    """``x`` with ``lam o x = r`` per cone (``lam`` inside the cone), stacked."""
    n = lam.size // 3
    out = np.empty(3 * n)
    for c in range(n):
        l0, l1, l2 = lam[3 * c], lam[3 * c + 1], lam[3 * c + 2]
        r0, r1, r2 = r[3 * c], r[3 * c + 1], r[3 * c + 2]
        tail = np.sqrt(l1 * l1 + l2 * l2)
        head = (l0 * r0 - (l1 * r1 + l2 * r2)) / ((l0 - tail) * (l0 + tail))
        out[3 * c] = head
        out[3 * c + 1] = (r1 - head * l1) / l0
        out[3 * c + 2] = (r2 - head * l2) / l0
    return out


@njit(cache=True, error_model="numpy")
def max_step(v, dv):
    """Largest ``t <= 1`` keeping ``v + t dv`` in every cone (:meth:`.cones.SecondOrderCones.max_step`)."""
    best = 1.0
    for c in range(v.size // 3):
        v0, v1, v2 = v[3 * c], v[3 * c + 1], v[3 * c + 2]
        d0, d1, d2 = dv[3 * c], dv[3 * c + 1], dv[3 * c + 2]
        a = d0 * d0 - (d1 * d1 + d2 * d2)
        b = v0 * d0 - (v1 * d1 + v2 * d2)
        tail = np.sqrt(v1 * v1 + v2 * v2)
        f0 = (v0 - tail) * (v0 + tail)
        disc = b * b - a * f0
        if disc >= 0.0:
            root = np.sqrt(disc)
            q = -(b + root) if b >= 0.0 else -(b - root)
            if a != 0.0 and 0.0 < q / a < best:
                best = q / a
            if q != 0.0 and 0.0 < f0 / q < best:
                best = f0 / q
        if d0 < 0.0 and -v0 / d0 < best:
            best = -v0 / d0
    return best
