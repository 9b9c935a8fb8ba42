"""The state of the deformable mode, stepped by the rigid mode's phases (:mod:`.simulation`) on nodes.

The state carries the node positions and velocities; ``pos`` (block, 3) is kept as the rigid-body
fit of every block's nodes after each chunk, which is what the post-processing and the
snapshots read.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from . import deformable, kernels
from .scene import Scene, face_properties
from .simulation import Controls, State


@dataclass
class DeformableState(State):
    mesh: deformable.Mesh | None = None
    x: np.ndarray | None = None
    y: np.ndarray | None = None
    node_vel: np.ndarray | None = None
    x_detect: np.ndarray | None = None
    y_detect: np.ndarray | None = None
    node_load: np.ndarray | None = None
    node_added: np.ndarray | None = None

    def set_loads(self, scene: Scene, load: np.ndarray, added: np.ndarray | None = None,
                  start: float = 0.0, duration: float = 0.0) -> None:
        """As for the rigid state, the loads shared among the nodes (:func:`.deformable.nodal_load`)."""
        super().set_loads(scene, load, added, start, duration)
        self.node_load = deformable.nodal_load(self.mesh, scene, self.load)
        self.node_added = deformable.nodal_load(self.mesh, scene, self.added)

    def fit_blocks(self, scene: Scene) -> None:
        """``pos``: the block positions of the rigid-body fit of the nodes."""
        fit = deformable.rigid_fit(self.mesh, self.x, self.y, scene.driven.size)
        cx0, cy0 = deformable.rigid_fit(self.mesh, self.mesh.x0, self.mesh.y0, scene.driven.size)[:, :2].T
        self.pos = scene.pos0 + np.stack((fit[:, 0] - cx0, fit[:, 1] - cy0, fit[:, 2]), axis=1)

    def detect(self, scene: Scene, controls: Controls, first: bool):
        """Face pairs of the current boundary (the rigid detection with the node positions as the
        block shapes at zero motion); contact history carried from the previous list."""
        n_poly = scene.lx.size
        zero = np.zeros_like(scene.pos0)
        faces = kernels.detect_face_pairs(zero, self.x[:n_poly], self.y[:n_poly], scene.offs, scene.driven,
                                          controls.buffer, controls.max_penetration, controls.min_cos)
        props, bonded_start = face_properties(scene, faces)
        shear = np.zeros((faces.shape[0], 2))
        energy = np.zeros((faces.shape[0], 2))
        if first:
            bonded = np.repeat(bonded_start[:, None], 2, axis=1).astype(np.int64)
        else:
            bonded = np.zeros((faces.shape[0], 2), dtype=np.int64)
            self.acc[kernels.RELEASED] += kernels.carry_history(
                kernels.face_keys(self.faces, n_poly), self.shear, self.bonded, self.energy,
                kernels.face_keys(faces, n_poly), shear, bonded, energy)
        self.faces, self.props, self.shear, self.bonded, self.energy = faces, props, shear, bonded, energy
        self.normal = np.zeros((faces.shape[0], 2))
        self.x_detect, self.y_detect = self.x.copy(), self.y.copy()

    def rebuild_pairs(self, scene: Scene, controls: Controls) -> None:
        self.detect(scene, controls, first=False)
        self.rebuilds += 1

    def advance_chunk(self, scene: Scene, controls: Controls, n_steps: int, rate: float, target: float,
                      out: np.ndarray) -> None:
        """One call of :func:`.deformable.advance`, then the rigid fit of the blocks."""
        m = self.mesh
        deformable.advance(n_steps, controls.dt, self.x, self.y, self.node_vel, m.x0, m.y0, self.x_detect,
                           self.y_detect, scene.offs, m.node_block, m.triangles, m.grad_x, m.grad_y, m.area0,
                           m.young, m.poisson, m.active_tri, m.mass, m.inv_mass, m.driven, scene.pos0,
                           scene.direction, self.faces, self.props, controls.kn, controls.kt,
                           controls.min_half, controls.contact_damping, self.shear, self.bonded, self.normal,
                           self.energy, self.node_load, controls.load_ramp, self.node_added, self.added_start,
                           self.added_time, controls.damping, rate, controls.ramp_time, self.settlement_start, target,
                           0.5 * controls.buffer, self.acc, out)
        self.fit_blocks(scene)


def deformable_controls(mesh: deformable.Mesh, scene: Scene, controls: Controls, dt_safety: float) -> Controls:
    """The rigid controls with the time step of the nodes (elements and contacts)."""
    dt_critical = deformable.critical_time_step(mesh, scene, controls.kn)
    dt = dt_safety * dt_critical
    record_steps = max(1, int(round(controls.record_steps * controls.dt / dt)))
    return replace(controls, dt=dt, dt_critical=dt_critical, record_steps=record_steps,
                   ramp_time=max(controls.ramp_time, dt))


def initial_state(scene: Scene, controls: Controls, mesh: deformable.Mesh, load: np.ndarray) -> DeformableState:
    state = DeformableState(
        pos=scene.pos0.copy(), vel=np.zeros_like(scene.pos0), pos_detect=scene.pos0.copy(),
        faces=np.zeros((0, 4), np.int64), props=np.zeros((0, 4)), shear=np.zeros((0, 2)),
        bonded=np.zeros((0, 2), np.int64), normal=np.zeros((0, 2)), energy=np.zeros((0, 2)),
        acc=np.zeros(kernels.N_ACC), active=(~scene.driven).astype(np.int64),
        calm=np.zeros(scene.driven.size, dtype=np.int64), face_force=np.zeros((0, 4)),
        mesh=mesh, x=mesh.x0.copy(), y=mesh.y0.copy(), node_vel=np.zeros((mesh.x0.size, 2)))
    state.set_loads(scene, load)
    state.detect(scene, controls, first=True)
    return state
