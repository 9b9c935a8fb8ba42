"""The time loop of rigid polyhedra: the 2D loop (:mod:`.simulation`: gravity to rest, the settlement ramp, the
plateau stop, records, Ctrl-C) on a state whose blocks also carry their orientations and angular velocities,
stepped by :mod:`.kernels3d`."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import kernels, kernels3d
from .controls import Controls
from .scene3d import Scene3, contacts, face_properties3, friction_between3, new_pairs
from .simulation import State


@dataclass
class State3(State):
    """The 2D :class:`.simulation.State` with ``pos`` the centroids (block, 3), ``vel`` their velocities, and
    the orientations (unit quaternions), angular velocities and orientations at the last detection."""

    quat: np.ndarray | None = None
    omega: np.ndarray | None = None
    quat_detect: np.ndarray | None = None

    def motion(self) -> kernels3d.Motion3:
        return kernels3d.Motion3(self.pos, self.quat, self.vel, self.omega, self.pos_detect, self.quat_detect,
                                 self.acc)

    def advance_chunk(self, scene: Scene3, controls: Controls, n_steps: int, rate: float, target: float,
                      wrench: np.ndarray) -> kernels.Report:
        """One call of the 3D stepping kernel (:func:`.kernels3d.advance3`)."""
        loading = kernels3d.Loading3(self.load, float(controls.load_ramp), float(rate), float(controls.ramp_time),
                                     float(self.settlement_start), float(target))
        return kernels.Report(*kernels3d.advance3(n_steps, scene.bodies, self.pairs, contact_law3(controls),
                                                  self.motion(), loading, stepping3(controls), wrench))

    def rebuild_pairs(self, scene: Scene3, controls: Controls) -> None:
        """New face pairs at the current positions, each kept one's points keeping their histories (a new pair
        starts unbonded, as in 2D)."""
        self.pairs = detect3(scene, controls, self.motion(), self.pairs)
        self.pos_detect = self.pos.copy()
        self.quat_detect = self.quat.copy()
        self.rebuilds += 1

    def snapshot(self) -> np.ndarray:
        """``(block, 7)``: the centroids and orientations."""
        return np.c_[self.pos, self.quat]

    def motions_from(self, scene: Scene3, reference: np.ndarray) -> np.ndarray:
        """``(block,)``: every free block's motion from the ``reference`` centroids at rest: its centroid's, plus
        its rotation's angle times its radius."""
        angle = 2.0 * np.arccos(np.minimum(np.abs(self.quat[:, 0]), 1.0))
        moved = np.linalg.norm(self.pos - reference, axis=1) + angle * scene.radius
        return np.where(scene.driven, 0.0, moved)

    def speeds(self, scene: Scene3) -> np.ndarray:
        return np.where(scene.driven, 0.0, np.linalg.norm(self.vel, axis=1)
                        + np.linalg.norm(self.omega, axis=1) * scene.radius)


def contact_law3(controls: Controls) -> kernels3d.ContactLaw3:
    """The contact constants as the 3D kernels take them: stiffnesses per area, the smallest overlap the square
    of the 2D shortest contact."""
    return kernels3d.ContactLaw3(float(controls.kn), float(controls.kt), float((2.0 * controls.min_half) ** 2),
                                 float(controls.contact_damping), float(controls.reclip),
                                 float(controls.buffer))


def stepping3(controls: Controls) -> kernels3d.Stepping3:
    return kernels3d.Stepping3(float(controls.dt), float(controls.damping), 0.5 * float(controls.buffer))


def detect3(scene: Scene3, controls: Controls, motion: kernels3d.Motion3,
            old: kernels3d.Pairs3 | None) -> kernels3d.Pairs3:
    """The face pairs at ``motion`` with their properties; those of ``old`` keep their points' histories, the
    first detection's pairs start bonded where their joint has a strength."""
    faces, corners, edges = contacts(scene.bodies, motion, controls.buffer, controls.max_penetration,
                                     controls.min_cos)
    props, bonded = face_properties3(scene, faces)
    return new_pairs(scene.bodies, faces, props, bonded if old is None else np.zeros(len(faces), bool), corners,
                     friction_between3(scene, corners[:, 1:]), edges, friction_between3(scene, edges[:, [1, 3]]), old)


def initial_state3(scene: Scene3, controls: Controls) -> State3:
    """Every block at rest where the model has it, the first face pairs found."""
    n = scene.driven.size
    quat = np.zeros((n, 4))
    quat[:, 0] = 1.0
    state = State3(pos=scene.pos0.copy(), vel=np.zeros((n, 3)), pos_detect=scene.pos0.copy(), pairs=None,
                   acc=np.zeros(kernels.N_ACC), active=(~scene.driven).astype(np.int64),
                   calm=np.zeros(n, dtype=np.int64), quat=quat, omega=np.zeros((n, 3)), quat_detect=quat.copy())
    state.pairs = detect3(scene, controls, state.motion(), None)
    return state
