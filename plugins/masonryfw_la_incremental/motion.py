"""Finite rigid motions: a block pose, its vertices, and a velocity field followed exactly over a step.

A pose is ``(ux, uy, theta)`` per block: the displacement of the centroid from the model's and the
rotation about it. A step moves each block by its own constant twist (centroid velocity ``v``, angular
velocity ``w``) over a parameter interval ``dt``: a rotation by ``w dt`` about the twist's fixed
instantaneous centre, or a translation when ``w`` is zero. A block turning about a hinge therefore
keeps the hinge where it is (a straight update of the centroid would move it by ``(w dt)^2 r / 2``
per step into or out of its neighbour). A moving support follows its ``settlement_direction`` the
same way from the start: a translating support translates, a support turning about a pivot turns
about that pivot by ``w t`` (the model's direction is that motion's velocity at the centroid).
"""
from __future__ import annotations

import numpy as np


def sinc_terms(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``sin(phi) / phi`` and ``(1 - cos(phi)) / phi``, continuous through ``phi = 0``."""
    small = np.abs(phi) < 1e-6
    safe = np.where(small, 1.0, phi)
    a = np.where(small, 1.0 - phi**2 / 6.0, np.sin(safe) / safe)
    b = np.where(small, phi / 2.0 - phi**3 / 24.0, (1.0 - np.cos(safe)) / safe)
    return a, b


def screw(twist: np.ndarray, dt: float | np.ndarray) -> np.ndarray:
    """``(block, 3)``: the centroid displacement and rotation of constant twists ``(vx, vy, w)`` over ``dt``."""
    twist = np.asarray(twist, dtype=float)
    phi = twist[:, 2] * dt
    a, b = sinc_terms(phi)
    vx, vy = twist[:, 0] * dt, twist[:, 1] * dt
    return np.c_[a * vx - b * vy, b * vx + a * vy, phi]


def vertices(pose: np.ndarray, centroid0: np.ndarray, node_x: np.ndarray, node_y: np.ndarray,
             owner: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The current vertex coordinates of every block's polygon."""
    theta = pose[owner, 2]
    dx, dy = node_x - centroid0[owner, 0], node_y - centroid0[owner, 1]
    c, s = np.cos(theta), np.sin(theta)
    return (centroid0[owner, 0] + pose[owner, 0] + c * dx - s * dy,
            centroid0[owner, 1] + pose[owner, 1] + s * dx + c * dy)


def current_twist(direction: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """The velocity per unit t, at their current centroids, of supports moving by ``direction`` from the model's
    (a constant twist: the rotation part carries the centroid's velocity round with it)."""
    w = direction[:, 2]
    return np.c_[direction[:, 0] - w * pose[:, 1], direction[:, 1] + w * pose[:, 0], w]
