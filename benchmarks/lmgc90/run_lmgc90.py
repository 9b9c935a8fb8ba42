"""LMGC90 (``compas_lmgc90`` on PyPI, MIT; rigid polyhedra, non-smooth contact dynamics, Coulomb friction without
dilatancy) on a masonryfw model written by ``bench_lmgc90.py`` as JSON: the supports driven at a constant rate along
their ``settlement_direction`` (after a velocity ramp), the settlement reaction recorded every ``--every`` steps
(the masonry's force and moment on each support from the contacts, weighted by the support's motion per unit of
the settlement, as ``masonryfw.settlement_reaction`` weighs them). Dead loads besides the blocks' weight (a model's
floors and roofs, ``extra_load``: a force per block through its centroid) are constant external forces from the start,
as gravity is.

Run it with the Python that has compas_lmgc90 (a separate environment: it pulls compas_viewer and Qt):
``python run_lmgc90.py model.json out.json --settlement 0.01 --time 2.0 --dt 0.002``.
"""
from __future__ import annotations

import argparse
import json
import time

import numpy as np

#: Each ground segment is narrowed by this much on each side: neighbouring segments driven apart or together
#: must not touch (a contact between two driven bodies makes LMGC90's problem singular: NaN), and LMGC90 looks
#: for contacts 1 mm away (its alert distance).
GAP = 1.5e-3  # m
RAMP = 0.05  # share of the settlement time over which the velocity ramps up from 0
COMPONENTS = ("Vx", "Vy", "Vz", "Rx", "Ry", "Rz")


def narrowed(vertices: np.ndarray) -> np.ndarray:
    """A box-like support's vertices pulled in horizontally by :data:`GAP` on each side about their mean."""
    centre = vertices.mean(axis=0)
    half = np.abs(vertices - centre).max(axis=0)
    return centre + (vertices - centre) * np.array([1 - GAP / half[0], 1 - GAP / half[1], 1.0])


def wrenches(result, centre: np.ndarray) -> np.ndarray:
    """(block, 6): the force and moment about its centroid on every body from its contacts (LMGC90's global
    contact force acts on the first body of a pair from the second)."""
    bodies = np.array([list(b) for b in result.interaction_bodies], dtype=int).reshape(-1, 2)
    base = 1 if bodies.size and bodies.min() >= 1 else 0
    out = np.zeros((centre.shape[0], 6))
    for (a, b), f, p in zip(bodies - base, result.interaction_force_global, result.interaction_coords):
        f, p = np.asarray(f), np.asarray(p)
        for body, sign in ((a, 1.0), (b, -1.0)):
            out[body, :3] += sign * f
            out[body, 3:] += sign * np.cross(p - centre[body], f)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("model")
    parser.add_argument("out")
    parser.add_argument("--settlement", type=float, required=True, help="settlement parameter to reach [m]")
    parser.add_argument("--time", type=float, required=True, help="time to reach it [s]")
    parser.add_argument("--dt", type=float, default=0.002)
    parser.add_argument("--every", type=int, default=20)
    args = parser.parse_args()
    from compas_lmgc90.solver import Solver

    spec = json.load(open(args.model))
    support = np.array(spec["role"]) >= 2
    direction, centre = np.array(spec["direction"]), np.array(spec["centroid"])
    blocks = [{**b, "vertices": narrowed(np.array(b["vertices"])).tolist()} if support[k] else b
              for k, b in enumerate(spec["blocks"])]
    density = spec["unit_weight"] / 9.81
    solver = Solver(dt=args.dt, theta=0.5, density=density)
    solver.geometry_from_v_f(blocks, density=density)
    rate, ramp = args.settlement / args.time, RAMP * args.time
    for b in np.flatnonzero(support):  # V(t) = v min(1, t / ramp): LMGC90's time function of a driven dof
        for k, name in enumerate(COMPONENTS):
            v = direction[b, k] * rate
            solver.apply_velocity(int(b), name, np.array([[v, 0.0, 0.0, 0.0, 0.0, 1.0 / ramp]]) if v else 0.0)
    for b, force in enumerate(spec["extra_load"]):
        for name, value in zip(("Fx", "Fy", "Fz"), force):
            if value:
                solver.apply_force(b, name, float(value))
    solver.contact_law("IQS_CLB", spec["friction"], alert=1e-3)
    solver.preprocess()
    steps = int(round((args.time + ramp / 2) / args.dt))
    rows, start = [], time.time()
    for step in range(1, steps + 1):
        solver.run(1)
        if step % args.every == 0 or step == steps:
            tau = step * args.dt
            settled = rate * (tau * tau / (2 * ramp) if tau < ramp else tau - ramp / 2)
            wrench = wrenches(solver.last_result, centre)
            rows.append((step, settled, float((wrench[support] * direction[support]).sum()),
                         float(wrench[support, 2].sum())))
    moved = np.array([np.asarray(b) for b in solver.last_result.bodies]) - centre
    json.dump({"rows": rows, "seconds": time.time() - start, "steps": steps, "displacement": moved.tolist()},
              open(args.out, "w"))


if __name__ == "__main__":
    main()
