"""The state of the deformable mode, stepped by the rigid mode's phases (:mod:`.simulation`) on nodes.

The state carries the node positions and velocities; ``pos`` (block, 3) is kept as the rigid-body
fit of every block's nodes after each chunk, which is what the post-processing and the
snapshots read.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from . import deformable, kernels
from .controls import Controls
from .costs import call_steps, step_seconds
from .scene import Scene
from .simulation import State, bodies, contact_law, detect, stepping


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
        self.pairs = detect(scene, controls, None if first else self, np.zeros_like(scene.pos0),
                            self.x[:n_poly], self.y[:n_poly])
        self.x_detect, self.y_detect = self.x.copy(), self.y.copy()

    def rebuild_pairs(self, scene: Scene, controls: Controls) -> None:
        self.detect(scene, controls, first=False)
        self.rebuilds += 1

    def advance_chunk(self, scene: Scene, controls: Controls, n_steps: int, rate: float, target: float,
                      wrench: np.ndarray) -> kernels.Report:
        """One call of :func:`.deformable.advance`, then the rigid fit of the blocks."""
        motion = deformable.NodeMotion(self.x, self.y, self.node_vel, self.x_detect, self.y_detect, self.acc)
        loading = self.loading(controls, rate, target)._replace(load=self.node_load, added=self.node_added)
        report = kernels.Report(*deformable.advance(n_steps, bodies(scene), self.mesh, self.pairs,
                                                    contact_law(controls), motion, loading, stepping(controls),
                                                    wrench))
        self.fit_blocks(scene)
        return report


def deformable_controls(mesh: deformable.Mesh, scene: Scene, controls: Controls, dt_safety: float) -> Controls:
    """The rigid controls with the time step of the nodes (elements and contacts)."""
    dt_critical = deformable.critical_time_step(mesh, scene, controls.kn)
    dt = dt_safety * dt_critical
    record_steps = max(1, int(round(controls.record_steps * controls.dt / dt)))
    return replace(controls, dt=dt, dt_critical=dt_critical, record_steps=record_steps,
                   call_steps=call_steps(step_seconds(scene.driven.size, scene.friction.size, deformable=True)), ramp_time=max(controls.ramp_time, dt))


def initial_state(scene: Scene, controls: Controls, mesh: deformable.Mesh, load: np.ndarray) -> DeformableState:
    state = DeformableState(
        pos=scene.pos0.copy(), vel=np.zeros_like(scene.pos0), pos_detect=scene.pos0.copy(),
        pairs=kernels.Pairs(np.zeros((0, 4), np.int64), np.zeros((0, 4)), np.zeros((0, 2)),
                            np.zeros((0, 2), np.int64), np.zeros((0, 2)), np.zeros((0, 2)), np.zeros((0, 4))),
        acc=np.zeros(kernels.N_ACC), active=(~scene.driven).astype(np.int64),
        calm=np.zeros(scene.driven.size, dtype=np.int64),
        mesh=mesh, x=mesh.x0.copy(), y=mesh.y0.copy(), node_vel=np.zeros((mesh.x0.size, 2)))
    state.set_loads(scene, load)
    state.detect(scene, controls, first=True)
    return state
