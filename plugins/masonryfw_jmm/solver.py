"""The ``jmm`` solve: gravity, then incremental settlement of the moving support to the reaction plateau."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import xarray as xr

import masonryfw as mf

from .newton import NewtonSolver, State
from .output import mesh_variables, point_variables, variable
from .problem import Problem, build_problem

MIN_INCREMENT = 1e-4  # of the elastic unloading settlement: below it a failing step stops the run


@dataclass
class History:
    settlement: list = field(default_factory=list)
    reaction: list = field(default_factory=list)
    iterations: list = field(default_factory=list)
    plastic_points: list = field(default_factory=list)
    residuals: list = field(default_factory=list)


GRAVITY_ITERATIONS = 4  # times max_iterations: with c = sigma_t = 0 the domain is a cone, so smaller
# gravity increments meet the same (scaled) problem and do not help; more iterations do


def _gravity_stage(newton: NewtonSolver, state: State, history: History) -> tuple[State, str]:
    """Apply gravity (halved when a step fails); all supports held."""
    factor, increment, iterations = 0.0, 1.0, 0
    while factor < 1.0:
        target = min(1.0, factor + increment)
        trial, report = newton.step(state, target, 0.0, GRAVITY_ITERATIONS * newton.max_iterations)
        iterations += report.iterations
        if report.converged:
            state, factor = trial, target
            continue
        increment /= 2
        if increment < 1e-3:
            return state, f"gravity stage did not converge at gravity factor {factor:.4f}"
    history.settlement.append(0.0)
    history.reaction.append(newton.reaction(state))
    history.iterations.append(iterations)
    history.plastic_points.append(int(state.active.any(axis=1).sum()))
    return state, ""


def elastic_unloading_settlement(newton: NewtonSolver, state: State) -> tuple[float, float]:
    """Settlement (non-dimensional) that would unload the support with the current tangent, and the slope."""
    trial, _ = newton.step(state, 1.0, 1.0, max_iterations=1)  # the tangent predictor alone: one linear solve
    p = newton.problem
    K = p.disc.stiffness(newton._regularised(state, False))  # the tangent the predictor solved with
    du = trial.u - state.u
    slope = float((K @ du)[p.moving[p.moving_vertical]].sum())
    reaction = newton.reaction(state)
    if not slope < 0 or not reaction > 0:
        raise mf.SolveError(
            f"jmm: the moving support carries {reaction:.3g} (non-dimensional) and unloads at slope {slope:.3g}: "
            "nothing to settle"
        )
    return reaction / -slope, slope


def _plateau(history: History, slope: float, options) -> bool:
    n = options["plateau_steps"]
    if len(history.settlement) < n + 2:
        return False
    s = np.asarray(history.settlement[-n - 1:])
    r = np.asarray(history.reaction[-n - 1:])
    return bool(np.all(np.abs(np.diff(r) / np.diff(s)) < options["plateau_slope"] * abs(slope)))


def run(problem: Problem, options, progress) -> tuple[State, History, dict]:
    """Gravity, then settlement steps until the plateau; every converged step kept."""
    kappa = options["vertex_stiffness"], options["settled_stiffness"]
    newton = NewtonSolver(problem, options["tolerance"], options["max_iterations"], regularisation=kappa)
    history = History()
    info = {"interrupted": 0, "stop_reason": ""}
    state = State.initial(problem)
    try:
        progress(0.0, "gravity")
        state, failure = _gravity_stage(newton, state, history)
        if failure:
            info["stop_reason"] = failure
            return state, history, info
        unloading, slope = elastic_unloading_settlement(newton, state)
        info["jmm_elastic_unloading_settlement_m"] = unloading * problem.displacement
        limit = (options["max_settlement"] / problem.displacement if options["max_settlement"] is not None
                 else 30 * unloading)
        increment, settlement = options["first_increment"] * unloading, 0.0
        largest = options["max_increment"] * unloading
        last_increment = None  # (du, ds) of the last converged step, extrapolated as a second predictor
        while True:
            if len(history.settlement) - 1 >= options["max_steps"]:
                info["stop_reason"] = f"max_steps ({options['max_steps']}) reached"
                break
            target = min(settlement + increment, limit)
            guess = None
            if last_increment is not None:
                du, ds = last_increment
                guess = state.u + (target - settlement) / ds * du
            trial, report = newton.step(state, 1.0, target, guess=guess)
            if not report.converged:
                increment /= 2
                if increment < MIN_INCREMENT * unloading:
                    info["stop_reason"] = f"no convergence at settlement {target * problem.displacement:.4g} m"
                    break
                continue
            last_increment = (trial.u - state.u, target - settlement)
            state, settlement = trial, target
            history.settlement.append(settlement)
            history.reaction.append(newton.reaction(state))
            history.iterations.append(report.iterations)
            history.plastic_points.append(int(state.active.any(axis=1).sum()))
            history.residuals.append(report.residuals)
            progress(min(0.99, settlement / limit), f"step {len(history.settlement) - 1}: settlement "
                     f"{settlement * problem.displacement:.3g} m, reaction {history.reaction[-1] * problem.force:.4g} N, "
                     f"{report.iterations} Newton iterations")
            if _plateau(history, slope, options):
                info["stop_reason"] = "reaction plateau"
                break
            if settlement >= limit:
                info["stop_reason"] = "max_settlement reached"
                break
            if report.iterations <= options["target_iterations"]:
                increment = min(1.5 * increment, largest)
            elif report.iterations > 2 * options["target_iterations"]:
                increment *= 0.5
    except KeyboardInterrupt:
        info["interrupted"] = 1
        info["stop_reason"] = "interrupted"
    return state, history, info


def result_dataset(problem: Problem, state: State, history: History, info: dict) -> xr.Dataset:
    """docs/format.md result variables (physical units) from the final converged state and the history."""
    p, disc = problem, problem.disc
    H, U = p.length, p.displacement
    vertex = disc.vertex_dofs()
    failure = np.zeros(disc.n_points, dtype=np.int8)
    failure[p.masonry_points] = p.return_map.failure_mode(state.active[p.masonry_points])
    qx, qy = disc.qp_xy * H
    stress = state.stress * p.stress
    variables = {
        **mesh_variables(disc.mesh.p * H, disc.mesh.t),
        "mesh_node_ux": variable("mesh_node", state.u[2 * vertex] * U, "m", "final horizontal displacement of the mesh node"),
        "mesh_node_uy": variable("mesh_node", state.u[2 * vertex + 1] * U, "m", "final vertical displacement of the mesh node"),
        **point_variables((qx, qy), failure, stress, "quadrature point", "in the last step"),
        "step_settlement": variable("step", np.asarray(history.settlement) * U, "m", "imposed settlement"),
        "step_reaction": variable("step", np.asarray(history.reaction) * p.force, "N",
                              "vertical reaction on the moving support"),
        "step_newton_iterations": variable("step", np.asarray(history.iterations, dtype=np.int32), "1",
                                       "Newton iterations of the step (step 0: the whole gravity stage)"),
        "step_plastic_points": variable("step", np.asarray(history.plastic_points, dtype=np.int32), "1",
                                    "quadrature points yielding in the step"),
    }
    iterations = np.asarray(history.iterations[1:], dtype=float)
    attrs = {
        **info,
        "jmm_beta": p.beta,
        "jmm_young_modulus_pa": p.young,
        "jmm_poisson_ratio": p.poisson,
        "jmm_dofs": int(disc.ndof),
        "jmm_quadrature_points": int(disc.n_points),
        "jmm_mean_newton_iterations": float(iterations.mean()) if iterations.size else 0.0,
    }
    return xr.Dataset(variables, attrs=attrs)


def solve(model: xr.Dataset, options, progress) -> xr.Dataset:
    """Solve ``model`` with the Jointed Masonry Model, settlement step by step: the ``jmm`` solver entry point."""
    problem = build_problem(model, options)
    state, history, info = run(problem, options, progress)
    if info["interrupted"] and len(history.settlement) == 0:
        raise KeyboardInterrupt  # interrupted before the gravity stage converged: nothing to keep
    progress(1.0, info["stop_reason"])
    return result_dataset(problem, state, history, info)
