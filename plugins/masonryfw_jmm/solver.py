"""The ``jmm`` solve: gravity, then incremental settlement of the moving support to the reaction plateau.

Without a moving support (a tilting table: the weight acting sideways as the live load),
the live load's factor grows instead, step by step under load control, until no step
converges (a step is cut in half when Newton fails, and the run ends when the increment
falls below ``load_tolerance``) or the factor has reached its plateau (it grows by less
than ``plateau_slope`` times the first step's rate per unit of the largest displacement
over ``plateau_steps`` steps): the last converged factor is the collapse multiplier."""
from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

import masonryfw as mf
import masonryfw.plugin_api as mfp

from .newton import NewtonSolver, State
from .output import block_mechanism, mesh_variables, point_variables, variable, with_mechanism
from .problem import Problem, build_problem

MIN_INCREMENT = 1e-4  # of the elastic unloading settlement: below it a failing step stops the run
#: The increments may grow to the target settlement over this many (a tunnel's S_max is often hundreds of
#: elastic unloading settlements away; without it max_steps ends the run first).
TARGET_STEPS = 50


@dataclass(frozen=True)
class Record:
    """One converged step (the first: the gravity stage), non-dimensional."""

    settlement: float
    reaction: float  # the settlement reaction
    load_factor: float
    displacement: float  # largest node displacement
    iterations: int
    plastic_points: int
    supports: np.ndarray  # (block,) upward force of each support on the wall
    crack_width: float  # crack band estimate (as u)
    crack_point: int  # the quadrature point where it is widest (-1: none)


@dataclass
class History:
    """The converged steps, each added whole as one record (a Ctrl-C never leaves a half one); the columns
    are read as lists (``history.reaction``)."""

    records: list = field(default_factory=list)
    # (settlement, u) of the last steps, for the mechanism: as many as the plateau test looks at, plus one
    recent: deque = field(default_factory=lambda: deque(maxlen=2))

    def add(self, newton: NewtonSolver, state: State, settlement: float, load_factor: float, iterations: int) -> None:
        p = newton.problem
        width, point = crack_band_width(p, state)
        record = Record(settlement, newton.reaction(state), load_factor,
                        float(np.hypot(state.u[0::2], state.u[1::2]).max(initial=0.0)), iterations,
                        int(state.active.any(axis=1).sum()),
                        np.bincount(p.support_of, weights=state.residual[p.support_uy], minlength=p.n_block),
                        width, point)
        recent = (settlement, state.u.copy())
        self.records.append(record)
        self.recent.append(recent)

    def __getattr__(self, name: str) -> list:
        """A column of the records, ``history.reaction`` for every record's ``reaction``."""
        if name in Record.__dataclass_fields__:
            return [getattr(r, name) for r in self.__dict__.get("records", [])]
        raise AttributeError(name)

    @property
    def steps(self) -> int:
        """Steps after the gravity stage."""
        return len(self.records) - 1


def crack_band_width(problem: Problem, state: State) -> tuple[float, int]:
    """Widest crack estimated from the plastic strain (non-dimensional, in the units of ``u``) and the
    quadrature point where it is (-1 when nothing opens).

    The smeared crack band (Bazant & Oh 1983): a crack that localises in one row of
    cells of size h opens by the plastic strain across it times h. At every masonry
    point the plastic strain ``strain - D^-1 stress`` is turned into the bed frame
    and its normal components, across the bed (yy) and across the head joints (xx),
    times the mesh size give the opening there; the widest over the points is returned.
    """
    p = problem
    plastic = state.strain - np.einsum("pij,pj->pi", p.compliance, state.stress)
    plastic = plastic[p.masonry_points]
    if p.from_bed is not None:  # engineering strains turn with the inverse transpose of the stress rotation
        plastic = np.einsum("pji,pj->pi", p.from_bed, plastic)
    opening = np.maximum(plastic[:, :2], 0.0).max(axis=1, initial=0.0)
    widest = int(np.argmax(opening)) if opening.size else 0
    if not opening.size or not opening[widest] > 0:
        return 0.0, -1
    return float(opening[widest] * p.mesh_size / p.length), int(np.flatnonzero(p.masonry_points)[widest])


GRAVITY_ITERATIONS = 4  # times max_iterations: with c = sigma_t = 0 the domain is a cone, so smaller
# gravity increments meet the same (scaled) problem and do not help; more iterations do
#: A round of the gravity stage that cut its residual at least this much, and ended within GRAVITY_STEADY of its
#: lowest (still falling, not oscillating: LACT3's portal went from 0.0177 to 0.197 in the round after one that
#: had touched 0.0013), goes on from where it got (another round from its last iterate) instead of halving the
#: increment and starting again; at most GRAVITY_ROUNDS times in a row.
GRAVITY_PROGRESS = 0.5
GRAVITY_STEADY = 1.5
GRAVITY_ROUNDS = 10


def _gravity_stage(newton: NewtonSolver, state: State, history: History,
                   progress=mfp.no_progress) -> tuple[State, str]:
    """Apply gravity in rounds of Newton iterations; all supports held. A round that did not converge but
    halved its residual, still falling at its end, is followed by another from its last iterate (the iterations
    on a big drawn wall converge linearly, 4-12 % an iteration: restarting from the last converged state threw a
    round's work away); any other halves the increment. Every Newton iteration is reported (on a big wall each
    takes seconds)."""
    factor, increment, iterations, rounds, guess = 0.0, 1.0, 0, 0, None
    while factor < 1.0:
        target = min(1.0, factor + increment)

        def iterated(k: int, residual: float, target: float = target) -> None:
            progress(0.0, f"gravity {target:.3g}: Newton iteration {k}, residual {residual:.2e} "
                          f"(converged at {newton.tolerance:.0e})")
        trial, report = newton.step(state, target, 0.0, GRAVITY_ITERATIONS * newton.max_iterations,
                                    guess=guess, iterated=iterated)
        iterations += report.iterations
        if report.converged:
            state, factor, rounds, guess = trial, target, 0, None
            continue
        last, best = report.residuals[-1], min(report.residuals)
        if rounds < GRAVITY_ROUNDS and last <= GRAVITY_PROGRESS * report.residuals[0] and last <= GRAVITY_STEADY * best:
            rounds, guess = rounds + 1, trial.u
            continue
        increment /= 2
        rounds, guess = 0, None
        if increment < 1e-3:
            x, y = _least_balanced(newton.problem, trial)
            return state, (f"gravity stage did not converge at gravity factor {factor:.4f} (the weight's share "
                           f"carried; least in balance near x {x:.3f} m, y {y:.3f} m)")
    history.add(newton, state, 0.0, 0.0, iterations)
    return state, ""


def _least_balanced(problem: Problem, trial: State) -> tuple[float, float]:
    """Where ``trial`` (a step that did not converge) is farthest from equilibrium: the mesh vertex of the largest
    free residual [m]."""
    vertex = problem.disc.vertex_dofs()
    residual = np.hypot(trial.residual[2 * vertex], trial.residual[2 * vertex + 1])
    residual[np.isin(2 * vertex + 1, problem.support_uy)] = 0.0  # a held vertex carries what it is given
    k = int(np.argmax(residual))
    return float(problem.disc.mesh.p[0, k] * problem.length), float(problem.disc.mesh.p[1, k] * problem.length)


def elastic_unloading_settlement(newton: NewtonSolver, state: State) -> tuple[float, float]:
    """Settlement (non-dimensional) that would unload the support with the current tangent, and the slope."""
    trial, _ = newton.step(state, 1.0, 1.0, max_iterations=1)  # the tangent predictor alone: one linear solve
    p = newton.problem
    K = p.disc.stiffness(newton._regularised(state, False))  # the tangent the predictor solved with
    du = trial.u - state.u
    slope = p.settlement_reaction(K @ du)
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


def _start(problem: Problem, options) -> tuple[NewtonSolver, History, dict, State]:
    """The Newton solver of a run, an empty history, the run's info and the initial state."""
    kappa = options["vertex_stiffness"], options["settled_stiffness"]
    newton = NewtonSolver(problem, options["tolerance"], options["max_iterations"], regularisation=kappa)
    history = History(recent=deque(maxlen=options["plateau_steps"] + 1))
    return newton, history, {"interrupted": 0, "stop_reason": ""}, State.initial(problem)


def _gravity(newton: NewtonSolver, state: State, history: History, info: dict, progress) -> tuple[State, bool]:
    """The gravity stage; ``(state, failed)``, the failure written into ``info``."""
    progress(0.0, "gravity")
    state, failure = _gravity_stage(newton, state, history, progress)
    info["stop_reason"] = failure
    return state, bool(failure)


@dataclass(frozen=True)
class Path:
    """What a run steps along, for :func:`_continue`: the settlement (settlement control) or the live load's factor
    (load control). ``step(newton, state, target, guess)`` is one Newton step to ``target``; the increment
    starts at ``first``, grows to at most ``largest`` and a failing step halves it down to ``smallest``; the
    target never passes ``limit``; ``failure(target, reached)`` says why the run ended when no step converges,
    ``record(newton, history, state, value, iterations)`` keeps a converged step (and says it),
    ``stop(history, value)`` why the run ends after one ("" to go on)."""

    step: Callable
    first: float
    largest: float
    smallest: float
    limit: float
    failure: Callable[[float, float], str]
    record: Callable
    stop: Callable[[History, float], str]


def _continue(newton: NewtonSolver, state: State, history: History, info: dict, path: Path, options) -> State:
    """Converged steps along ``path`` until it stops, the step limit, no step converges or Ctrl-C (``info``'s
    ``stop_reason``); returns the last converged state. A step that needs few Newton iterations grows the next
    increment by half, one that needs many halves it. The last converged increment, extrapolated, is the next
    step's predictor."""
    value, increment, last = 0.0, path.first, None
    try:
        while True:
            if history.steps >= options["max_steps"]:
                info["stop_reason"] = f"max_steps ({options['max_steps']}) reached"
                return state
            target = min(value + increment, path.limit)
            guess = None if last is None else state.u + (target - value) / last[1] * last[0]
            trial, report = path.step(newton, state, target, guess)
            if not report.converged:
                increment /= 2
                if increment < path.smallest:
                    info["stop_reason"] = path.failure(target, value)
                    return state
                continue
            last = (trial.u - state.u, target - value)
            state, value = trial, target
            path.record(newton, history, state, value, report.iterations)
            stop = path.stop(history, value)
            if stop:
                info["stop_reason"] = stop
                return state
            if report.iterations <= options["target_iterations"]:
                increment = min(1.5 * increment, path.largest)
            elif report.iterations > 2 * options["target_iterations"]:
                increment *= 0.5
    except KeyboardInterrupt:
        _interrupted(info)
        return state


def _interrupted(info: dict) -> None:
    info["interrupted"] = 1
    info["stop_reason"] = "interrupted"


def _settlement_path(problem: Problem, options, unloading: float, slope: float, progress) -> Path:
    """Settlement control: from ``first_increment`` elastic unloading settlements (``unloading``) to the target
    (or 30 of them), until the reaction plateau."""
    limit = options["settlement"] / problem.displacement if options["settlement"] is not None else 30 * unloading
    largest = options["max_increment"] * unloading
    if options["settlement"] is not None:  # a target far away: reachable in TARGET_STEPS full increments
        largest = max(largest, limit / TARGET_STEPS)

    def record(newton, history, state, settlement, iterations):
        history.add(newton, state, settlement, 0.0, iterations)
        progress(min(0.99, settlement / limit), f"step {history.steps}: settlement "
                 f"{settlement * problem.displacement:.3g} m, reaction {history.reaction[-1] * problem.force:.4g} N, "
                 f"{iterations} Newton iterations")

    def stop(history, settlement):
        if _plateau(history, slope, options):
            return "reaction plateau"
        return "target settlement reached" if settlement >= limit else ""

    return Path(step=lambda newton, state, target, guess: newton.step(state, 1.0, target, guess=guess),
                first=options["first_increment"] * unloading, largest=largest, smallest=MIN_INCREMENT * unloading,
                limit=limit, failure=lambda target, reached: f"no convergence at settlement "
                f"{target * problem.displacement:.4g} m", record=record, stop=stop)


def _load_path(options, progress) -> Path:
    """Load control: the live load's factor from ``load_increment`` until no step converges (the limit load) or the
    load plateau."""
    def record(newton, history, state, factor, iterations):
        history.add(newton, state, 0.0, factor, iterations)
        progress(min(0.99, history.steps / options["max_steps"]),
                 f"step {history.steps}: load factor {factor:.4g}, {iterations} Newton iterations")

    return Path(step=lambda newton, state, target, guess: newton.step(state, 1.0, 0.0, guess=guess,
                                                                      load_factor=target),
                first=options["load_increment"], largest=math.inf, smallest=options["load_tolerance"],
                limit=math.inf, failure=lambda target, reached: f"no convergence above load factor {reached:.6g}: "
                "the limit load", record=record,
                stop=lambda history, factor: "load plateau" if _load_plateau(history, options) else "")


def run(problem: Problem, options, progress) -> tuple[State, History, dict]:
    """Gravity, then settlement steps until the plateau (or the target); every converged step kept."""
    def settling(newton: NewtonSolver, state: State, info: dict) -> Path:
        unloading, slope = elastic_unloading_settlement(newton, state)
        info["jmm_elastic_unloading_settlement_m"] = unloading * problem.displacement
        return _settlement_path(problem, options, unloading, slope, progress)
    return _gravity_then(problem, options, progress, settling)


def _load_plateau(history: History, options) -> bool:
    """The load factor has grown by less than ``plateau_slope`` times its first-step rate per unit of the
    largest displacement over the last ``plateau_steps`` steps: the structure yields without more load."""
    n = options["plateau_steps"]
    if history.steps < n + 1:
        return False
    factor, moved = np.asarray(history.load_factor), np.asarray(history.displacement)
    first = (factor[1] - factor[0]) / max(moved[1] - moved[0], 1e-300)
    rate = np.diff(factor[-n - 1:]) / np.maximum(np.diff(moved[-n - 1:]), 1e-300)
    return bool(np.all(rate < options["plateau_slope"] * first))


def run_load_factor(problem: Problem, options, progress) -> tuple[State, History, dict]:
    """Gravity, then load steps of the live load until no step converges (module docstring)."""
    return _gravity_then(problem, options, progress, lambda newton, state, info: _load_path(options, progress))


def _gravity_then(problem: Problem, options, progress, path: Callable[[NewtonSolver, State, dict], Path]):
    """The gravity stage, then the steps along ``path(newton, state at rest, info)``: ``(last state, history,
    info)``, what was converged kept on Ctrl-C."""
    newton, history, info, state = _start(problem, options)
    try:
        state, failed = _gravity(newton, state, history, info, progress)
        if not failed:
            state = _continue(newton, state, history, info, path(newton, state, info), options)
    except KeyboardInterrupt:
        _interrupted(info)
    return state, history, info


def load_factor_variables(history: History, displacement: float) -> dict:
    """The load-factor run's history and its collapse multiplier (the last converged factor)."""
    return {
        "collapse_multiplier": variable((), history.load_factor[-1], "1",
                                        "multiplier of the live load at the last converged step (the limit load)"),
        "step_load_factor": variable("step", np.asarray(history.load_factor), "1", "multiplier of the live load"),
        "step_largest_displacement": variable("step", np.asarray(history.displacement) * displacement, "m",
                                              "largest displacement of a mesh node"),
    }


def mechanism(problem: Problem, model: xr.Dataset, history: History) -> np.ndarray | None:
    """Block motions (block, 3) [m, rad] of the last steps: the displacement increment over the steps the
    plateau test looks at, projected onto each block's rigid motions (:func:`masonryfw.plugin_api.rigid_fit`) at the
    quadrature points; the supports move by their settlement increment. None before two steps."""
    if len(history.recent) < 2:
        return None
    (s0, u0), (s1, u1) = history.recent[0], history.recent[-1]
    p, disc = problem, problem.disc
    du = (u1 - u0)[disc.edofs]  # (el, 2 nb)
    ux = np.einsum("eqn,en->eq", disc.values, du[:, 0::2]).ravel()
    uy = np.einsum("eqn,en->eq", disc.values, du[:, 1::2]).ravel()
    return block_mechanism(model, np.repeat(p.mesh.block, disc.nqp), *(disc.qp_xy * p.length),
                           ux * p.displacement, uy * p.displacement, disc.weights.ravel(), (s1 - s0) * p.displacement)


def crack_interfaces(problem: Problem, model: xr.Dataset, history: History) -> np.ndarray:
    """Per record, the joint within the masonry nearest to the point of the widest crack band (-1: none)."""
    point = np.asarray(history.crack_point, dtype=np.int64)
    out = np.full(point.size, -1, dtype=np.int32)
    cracked = point >= 0
    if cracked.any():
        role = model.block_role.values
        inside = mfp.masonry_blocks(role)[model.interface_blocks.values.astype(np.int64)].all(axis=1)
        qx, qy = problem.disc.qp_xy * problem.length
        out[cracked] = mfp.nearest_interface(model, qx[point[cracked]], qy[point[cracked]],
                                            0.25 * problem.mesh_size, among=inside)
    return out


def result_dataset(problem: Problem, model: xr.Dataset, state: State, history: History, info: dict) -> xr.Dataset:
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
        **(load_factor_variables(history, U) if p.searches_load else {
            "step_settlement": variable("step", np.asarray(history.settlement) * U, "m", "imposed settlement"),
            "step_reaction": ("step", np.asarray(history.reaction) * p.force, mfp.variable_attrs("step_reaction")),
            "step_support_reaction": variable(("step", "block"), np.array(history.supports) * p.force, "N",
                                              mfp.variable_attrs("step_support_reaction")["long_name"]),
            "step_crack_width_max": variable(
                "step", np.asarray(history.crack_width) * U, "m",
                "widest crack estimated as the plastic opening strain across the joints times the mesh size "
                "(a smeared crack band, Bazant & Oh 1983)"),
            "step_crack_interface": ("step", crack_interfaces(p, model, history),
                                     mfp.variable_attrs("step_crack_interface")),
        }),
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


#: The plateau slope when the target is not the model's own (share of the elastic slope).
PLATEAU_SLOPE = 0.01


def with_targets(model: xr.Dataset, options) -> dict:
    """The options with the automatic target and plateau resolved: the settlement, else the model's
    settlement_target (None: 30 elastic unloading settlements); no plateau stop when the run goes to the
    model's target (the damage there is the answer), else :data:`PLATEAU_SLOPE`."""
    own_target = options["settlement"] is None and "settlement_target" in model
    settlement = float(model.settlement_target.values) if own_target else options["settlement"]
    slope = options["plateau_slope"] if options["plateau_slope"] is not None else 0.0 if own_target else PLATEAU_SLOPE
    return {**options, "settlement": settlement, "plateau_slope": slope}


def solve(model: xr.Dataset, options, progress) -> xr.Dataset:
    """Solve ``model`` with the Jointed Masonry Model, settlement (or load factor) step by step: the ``jmm``
    solver entry point."""
    options = with_targets(model, options)
    problem = build_problem(model, options)
    state, history, info = (run_load_factor if problem.searches_load else run)(problem, options, progress)
    if info["interrupted"] and len(history.iterations) == 0:
        raise KeyboardInterrupt  # interrupted before the gravity stage converged: nothing to keep
    if len(history.iterations) == 0:
        raise mf.SolveError(f"jmm: the wall does not stand under its own weight in the jointed continuum: "
                            f"{info['stop_reason']}; a finer mesh_size, or la or fdem on the blocks themselves")
    if not info["interrupted"]:  # an interrupted run leaves the bar where it stopped
        progress(1.0, info["stop_reason"])
    flow = "associative" if options["dilatancy"] is None else "nonassociative"  # the continuum's flow rule
    return with_mechanism(result_dataset(problem, model, state, history, info), mechanism(problem, model, history), flow)
