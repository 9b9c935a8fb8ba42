"""fdem-3D and la-3D against LMGC90 (a second physics: non-smooth contact dynamics of rigid polyhedra, Coulomb
friction without dilatancy, through ``compas_lmgc90`` on PyPI) on the corner building of ``masonryfw.testing``
(two walls toothed at a corner, a door, 134 blocks over a Gaussian trough) to 10 mm, or with ``--model WALL`` on
a bundled 3D model or a bundled wall's 3D twin (``mfp.twin``) to ``--settlement``: the settlement reaction against the settlement, its
minimum, the walls' final widest cracks (fdem), which blocks follow the ground.

LMGC90 runs in its own environment (it pulls compas_viewer and Qt): ``--lmgc-python`` names that Python, e.g.
``python3 -m venv /tmp/lmgc && /tmp/lmgc/bin/pip install compas_lmgc90``; its driver is
``benchmarks/lmgc90/run_lmgc90.py``. Rewrites the section "lmgc90" (a wall: "lmgc90-WALL") of docs/benchmarks.md.
"""
from __future__ import annotations

import json
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np
from _report import command_line, write_section

import masonryfw as mf
import masonryfw.plugin_api as mfp
import masonryfw.testing as mt

SETTLEMENT = 0.01  # m, the corner building's
DRIVER = Path(__file__).resolve().parent / "lmgc90" / "run_lmgc90.py"


def blocks_json(model) -> dict:
    """The model's blocks (vertices, faces by vertex), roles, support motions, centroids, weight, friction."""
    counts = model.block_node_count.values.astype(int)
    face_counts = model.block_face_count.values.astype(int)
    nodes = np.c_[model.node_x.values, model.node_y.values, model.node_z.values]
    face_sizes, face_nodes = model.face_node_count.values.astype(int), model.face_nodes.values.astype(int)
    faces = np.split(face_nodes, np.cumsum(face_sizes)[:-1])
    blocks = [{"vertices": part.tolist(), "faces": [f.tolist() for f in block_faces]}
              for part, block_faces in zip(np.split(nodes, np.cumsum(counts)[:-1]),
                                           np.split(np.array(faces, dtype=object), np.cumsum(face_counts)[:-1]))]
    return {"blocks": blocks, "role": model.block_role.values.tolist(),
            "direction": model.settlement_direction.values.tolist(),
            "centroid": np.c_[model.block_centroid_x.values, model.block_centroid_y.values,
                              model.block_centroid_z.values].tolist(),
            "unit_weight": float(model.block_unit_weight.values.max()),
            "friction": float(model.interface_friction.values.max()), "extra_load": extra_loads(model)}


def extra_loads(model) -> list[list[float]]:
    """(block, 3): each block's dead load besides its weight (floors, roofs), a force through its centroid as the model
    gives it. The driver applies it from the start with gravity: without it the bundled house is 25 % lighter (its
    LMGC90 run of 2026-12-07 left it out and came out 0.19 R0 under la's bound)."""
    if "dead_moment" in model and np.abs(model.dead_moment.values).max(initial=0.0) > 0:
        raise SystemExit("bench_lmgc90: the model carries dead moments (dead_moment); the LMGC90 driver applies forces "
                         "through the centroids only")
    weight = model.block_unit_weight.values * model.block_volume.values
    extra = np.array(model.dead_load.values, dtype=float)
    extra[:, 2] += weight
    extra[np.abs(extra) <= 1e-9 * max(weight.max(initial=0.0), 1.0)] = 0.0
    support = model.block_role.values >= 2
    extra[support] = 0.0  # driven bodies: their loads do nothing
    return extra.tolist()


def following(motion_z: np.ndarray, masonry: np.ndarray, settlement: float) -> np.ndarray:
    """The masonry blocks that went down by more than half the settlement: those following the ground."""
    return masonry & (motion_z < -0.5 * settlement)


def main() -> None:
    parser = command_line(__doc__)
    parser.add_argument("--lmgc-python", required=True, help="the Python that has compas_lmgc90")
    parser.add_argument("--times", type=float, nargs="+", default=[2.0, 4.0],
                        help="LMGC90's time to reach the settlement [s] (each a run)")
    parser.add_argument("--model", default="corner",
                        help="corner (the kit's corner building), a bundled 3D model or a bundled wall (its twin)")
    parser.add_argument("--fdem", action="append", default=None,
                        help="fdem's options for one run, KEY=VALUE[;KEY=VALUE] (repeatable; an empty string: the "
                             "defaults; default: the defaults and the contacts half as stiff, as the old default)")
    parser.add_argument("--settlement", type=float, default=SETTLEMENT, help="the settlement to reach [m]")
    args = parser.parse_args()
    args.fdem = args.fdem if args.fdem is not None else ["", "penetration_ratio=1e-4;rotational_inertia=physical"]
    settlement = args.settlement
    model = mt.corner_building() if args.model == "corner" else mf.open_model(args.model)
    model = model if mfp.space(model) == 3 else mf.checked_model(mfp.twin(model))
    masonry = mfp.masonry_blocks(model.block_role.values)
    with tempfile.TemporaryDirectory() as folder:
        spec = Path(folder) / "model.json"
        spec.write_text(json.dumps(blocks_json(model)))
        lmgc = {}
        for seconds in args.times:
            out = Path(folder) / f"lmgc-{seconds}.json"
            subprocess.run([args.lmgc_python, str(DRIVER), str(spec), str(out), "--settlement", repr(settlement),
                            "--time", repr(seconds)], check=True)
            lmgc[seconds] = json.loads(out.read_text())
    fdem = {}
    for variant in args.fdem:
        start = time.perf_counter()
        options = dict(pair.split("=", 1) for pair in variant.split(";") if pair)
        fdem[variant or "defaults"] = (mf.solve(model, "fdem", {"settlement": repr(settlement), **options}),
                                       time.perf_counter() - start)
    la = mf.solve(model, "la")
    la_non = mf.solve(model, "la", {"flow": "nonassociative"})
    r0 = float({n.name: n.value for n in mf.key_numbers(next(iter(fdem.values()))[0])}["dead_reaction"])
    collapse = float({n.name: n.value for n in mf.key_numbers(la)}["collapse_reaction"])
    collapse_non = float({n.name: n.value for n in mf.key_numbers(la_non)}["collapse_reaction"])
    grid = np.linspace(0.0, settlement, 41)[1:]
    later = grid >= 1e-3
    reference = np.array(lmgc[args.times[0]]["rows"])
    reference_curve = np.interp(grid, reference[:, 1], reference[:, 2])
    ground = following(np.array(lmgc[args.times[0]]["displacement"])[:, 2], masonry, settlement)
    body = ["Reactions as shares of fdem's R0 "
            f"({r0 / 1e3:.4g} kN); the differences against LMGC90's first run over the settlement (all of it, "
            "and from 1 mm on); Jaccard of the blocks following the ground (down by more than half the "
            "settlement).", "",
            "| run | s | reaction at 0.5, 1, 2, 5, 10 mm / R0 | minimum / R0 | max diff / R0 (from 1 mm) | "
            "following the ground | Jaccard |", "|---|---|---|---|---|---|---|"]
    at = np.array([0.5e-3, 1e-3, 2e-3, 5e-3, 10e-3])

    def row(label, seconds, s, r, moved_z):
        curve = np.interp(grid, s, r)
        diff = np.abs(curve - reference_curve)
        mine = following(moved_z, masonry, settlement)
        jaccard = (mine & ground).sum() / max((mine | ground).sum(), 1)
        body.append(f"| {label} | {seconds:.0f} | {', '.join(f'{v / r0:.4f}' for v in np.interp(at, s, r))} | "
                    f"{r[s > 0].min() / r0:.4f} | {diff.max() / r0:.4f} ({diff[later].max() / r0:.4f}) | "
                    f"{int(mine.sum())} | {jaccard:.2f} |")

    for seconds, run in lmgc.items():
        rows = np.array(run["rows"])
        row(f"LMGC90, {settlement / seconds * 1e3:.2g} mm/s, {run['steps']} steps", run["seconds"], rows[:, 1],
            rows[:, 2], np.array(run["displacement"])[:, 2])
    for variant, (result, seconds) in fdem.items():
        settling = result.step_phase.values == 1
        widest = result.step_wall_crack_width_max.values[-1] if "step_wall_crack_width_max" in result else \
            result.step_crack_width_max.values[-1:]
        widths = ", ".join(f"{w * 1e3:.3g}" for w in widest)
        row(f"fdem, {variant.replace(';', ', ')} (widest cracks {widths} mm)", seconds,
            result.step_settlement.values[settling], result.step_reaction.values[settling],
            result.block_displacement.values[:, 2])
    wanders = "" if la_non.attrs["la_flow_converged"] else f" (not converged: {la_non.attrs['stop_reason']})"
    body += ["", f"la (associative, the cone): alpha {float(la.collapse_multiplier):.4f}, collapse reaction "
             f"(1 - alpha) R0 = {collapse / r0:.4f} of fdem's R0. la non-associative: alpha "
             f"{float(la_non.collapse_multiplier):.4f}, collapse reaction {collapse_non / r0:.4f} of fdem's R0{wanders}."]
    print("\n".join(body))
    if args.model == "corner":
        write_section("lmgc90", "fdem-3D and la-3D against LMGC90 on the corner building", "\n".join(body))
    else:
        write_section(f"lmgc90-{args.model}", f"fdem-3D and la-3D against LMGC90 on {model.attrs.get('title')}",
                      "\n".join(body))


if __name__ == "__main__":
    main()
