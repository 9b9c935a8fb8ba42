"""The time loop: gravity until rest, then the settlement ramp or the load-factor search, in numba chunks.

Without a moving support, a model with a live load (a tilting table: the weight
acting sideways) gets the **load-factor search** instead: from the state at rest,
the live load is raised smoothly to a trial multiplier and held until the wall is at
rest again (stable: the trial becomes the new lower bound and the new start) or some
block has moved ``collapse_motion`` from where it rested (unstable: the upper bound;
the start is restored). Trials double from ``search_first`` until one is unstable,
then bisect the bracket to ``search_tolerance``. The largest stable multiplier is the
collapse multiplier; the final state is the last unstable trial's, which shows the
mechanism.

Python only decides between chunks: rebuilds the face-pair list when the
kernel asks for it, records the history, checks the rest and plateau criteria,
reports progress. A KeyboardInterrupt between or inside chunks ends the run
with the state reached so far (``interrupted``).
"""
from __future__ import annotations

import copy
import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numba
import numpy as np

import masonryfw as mf

from . import kernels
from .controls import Controls
from .scene import Scene, face_properties

LOG = logging.getLogger("masonryfw.fdem")
GRAVITY_PHASE, SETTLEMENT_PHASE, SEARCH_PHASE = 0, 1, 2
# Kinetic energy (in units of the wall's weight times the model size) no run can reach by falling:
# the whole wall falling a thousand times its own size. Beyond it the integration has blown up.
UNSTABLE_KINETIC_ENERGY = 1e3
GRAVITY_TIME_LIMIT = 20.0  # scaled time units (sqrt(length / g)) for the gravity phase to come to rest
#: The gravity phase running this many times its estimated steps (:mod:`.estimate`) is said, once.
OVERRUN = 5.0
#: A block that moves more than this share of the median unit height in the gravity phase: the masonry does not
#: stand under its own weight as built (elastic settling is a few thousandths of a unit).
STAND_SHARE = 0.1


@dataclass(frozen=True)
class Record:
    """One recorded chunk: the scalars (:attr:`History.COLUMNS`), every support's upward force on the wall
    and the widest openings (None: not measured)."""

    row: tuple
    supports: np.ndarray
    cracks: mf.Cracks | None


@dataclass
class History:
    """The records of a run, each added whole (one append: a Ctrl-C never leaves a half record).

    ``weights`` are the settlement weights of the scene's supports (``mfp.settlement_weights``, the rotation's
    made non-dimensional like the moments): the ``reaction`` column is the settlement reaction
    (``mf.settlement_reaction``) of the supports' wrenches. ``opening`` measures the widest openings of block positions (set by the solver).
    """

    weights: np.ndarray
    records: list = field(default_factory=list)
    snapshots: list = field(default_factory=list)  # (settlement, the state's snapshot)
    opening: Callable[..., mf.Cracks] | None = None
    vertical: int = 1  # the up component of a wrench (2 in 3D)

    COLUMNS = ("phase", "time", "settlement", "reaction", "kinetic", "stored", "work_gravity",
               "work_support", "dissipated_damping", "dissipated_friction", "released", "unbalanced", "load_factor")

    def add(self, phase: int, state: State, chunk: Chunk, load_factor: float = 0.0) -> None:
        acc = state.acc
        wrench = chunk.wrench  # the wall's action on each support
        row = (phase, acc[kernels.TIME], acc[kernels.SETTLEMENT], float((wrench * self.weights).sum()),
               chunk.report.kinetic, chunk.report.stored, acc[kernels.WORK_GRAVITY], acc[kernels.WORK_SUPPORT],
               acc[kernels.DISSIPATED_DAMPING], acc[kernels.DISSIPATED_FRICTION], acc[kernels.RELEASED],
               chunk.report.unbalanced, load_factor)
        cracks = self.opening(state.snapshot()) if self.opening is not None else None
        self.records.append(Record(row, -wrench[:, self.vertical], cracks))

    def table(self) -> dict[str, np.ndarray]:
        data = np.asarray([r.row for r in self.records], dtype=float).reshape(-1, len(self.COLUMNS))
        return {name: data[:, i] for i, name in enumerate(self.COLUMNS)}


@dataclass(frozen=True)
class Chunk:
    """The end of a run of steps: the last kernel call's :class:`.kernels.Report` and the wall's force and
    moment on every support (block, 3; 0 for the other blocks)."""

    report: kernels.Report
    wrench: np.ndarray


@dataclass
class State:
    pos: np.ndarray
    vel: np.ndarray
    pos_detect: np.ndarray
    pairs: kernels.Pairs  # the face pairs and their contact histories
    acc: np.ndarray
    active: np.ndarray  # (block,) 1 while integrated (free blocks not asleep)
    calm: np.ndarray  # (block,) consecutive slow steps
    steps: int = 0
    rebuilds: int = 0
    gravity_steps: int = 0
    settlement_start: float = 0.0
    stop_reason: str = ""
    interrupted: bool = False
    gravity_motion: np.ndarray | None = None  # (block,) how far each block moved in the gravity phase (scaled)
    fell: bool = False  # a block moved more than STAND_SHARE of a unit in the gravity phase
    collapse_bracket: tuple = ()  # (largest stable, smallest unstable load factor) of the search
    last_stable: State | None = None  # the search's state at rest under the largest stable load factor
    trials: list = field(default_factory=list)  # (load factor, stable, motion) of the load-factor search
    load: np.ndarray | None = None  # (block, 3) applied with the smooth start of the run
    added: np.ndarray | None = None  # (block, 3) applied on top, ramped from added_start over added_time
    added_start: float = 0.0
    added_time: float = 0.0

    def set_loads(self, scene: Scene, load: np.ndarray, added: np.ndarray | None = None,
                  start: float = 0.0, duration: float = 0.0) -> None:
        """The loads of the following steps: ``load``, and ``added`` ramped in from ``start`` over ``duration``."""
        self.load = load
        self.added = np.zeros_like(load) if added is None else added
        self.added_start, self.added_time = start, duration

    def loading(self, controls: Controls, rate: float, target: float) -> kernels.Loading:
        """The loads and the settlement of the next steps, as the kernels take them."""
        return kernels.Loading(self.load, float(controls.load_ramp), self.added, float(self.added_start),
                               float(self.added_time), float(rate), float(controls.ramp_time),
                               float(self.settlement_start), float(target))

    def advance_chunk(self, scene: Scene, controls: Controls, n_steps: int, rate: float, target: float,
                      wrench: np.ndarray) -> kernels.Report:
        """One call of the rigid stepping kernel (:func:`.kernels.advance`)."""
        motion = kernels.Motion(self.pos, self.vel, self.pos_detect, self.active, self.calm, self.acc)
        return kernels.Report(*kernels.advance(n_steps, bodies(scene), self.pairs, contact_law(controls), motion,
                                               self.loading(controls, rate, target), stepping(controls), wrench))

    def rebuild_pairs(self, scene: Scene, controls: Controls) -> None:
        """New face pairs at the current positions; every free block wakes (the new pairs have no frozen
        forces)."""
        self.pairs = detect(scene, controls, self, self.pos)
        self.active[~scene.driven] = 1
        self.calm[:] = 0
        self.pos_detect = self.pos.copy()
        self.rebuilds += 1

    def snapshot(self) -> np.ndarray:
        """What the blocks' displacements are made of (:func:`.postprocess.block_displacement`): the positions."""
        return self.pos.copy()

    def motions_from(self, scene: Scene, reference: np.ndarray) -> np.ndarray:
        """``(block,)``: every free block's motion from ``reference`` positions (:func:`block_motions`)."""
        return block_motions(scene, self.pos, reference)

    def speeds(self, scene: Scene) -> np.ndarray:
        """``(block,)``: every free block's speed, centroid plus spin times radius (0 for the driven ones)."""
        return np.where(scene.driven, 0.0, np.hypot(*self.vel[:, :2].T) + np.abs(self.vel[:, 2]) * scene.radius)


def contact_law(controls: Controls) -> kernels.ContactLaw:
    """The contact constants as the kernels take them."""
    return kernels.ContactLaw(float(controls.kn), float(controls.kt), float(controls.min_half),
                              float(controls.contact_damping))


def stepping(controls: Controls) -> kernels.Stepping:
    """The time step, damping and sleeping constants as the kernels take them."""
    return kernels.Stepping(float(controls.dt), float(controls.damping), 0.5 * float(controls.buffer),
                            float(controls.sleep_speed), int(controls.sleep_steps), float(controls.wake_force))


def bodies(scene: Scene) -> kernels.Bodies:
    """The scene's blocks as the kernels take them."""
    return kernels.Bodies(scene.pos0, scene.radius, scene.lx, scene.ly, scene.offs, scene.mass, scene.inv_mass,
                          scene.free, scene.driven, scene.moving, scene.direction)


def detect(scene: Scene, controls: Controls, state: State | None, pos: np.ndarray,
           lx: np.ndarray | None = None, ly: np.ndarray | None = None) -> kernels.Pairs:
    """Face pairs at ``pos`` (the blocks' shapes ``lx``, ``ly``, default the scene's) with their properties;
    contact history carried from ``state`` (the spring energy of pairs the rebuild drops is added to the
    released energy)."""
    lx = scene.lx if lx is None else lx
    ly = scene.ly if ly is None else ly
    faces = kernels.detect_face_pairs(pos, lx, ly, scene.offs, scene.driven,
                                      controls.buffer, controls.max_penetration, controls.min_cos)
    props, bonded_start = face_properties(scene, faces)
    shear = np.zeros((faces.shape[0], 2))
    energy = np.zeros((faces.shape[0], 2))
    if state is None:
        bonded = np.repeat(bonded_start[:, None], 2, axis=1).astype(np.int64)
    else:
        bonded = np.zeros((faces.shape[0], 2), dtype=np.int64)
        n_node = scene.lx.size
        old = state.pairs
        state.acc[kernels.RELEASED] += kernels.carry_history(
            kernels.face_keys(old.faces, n_node), old.shear, old.bonded, old.energy,
            kernels.face_keys(faces, n_node), shear, bonded, energy)
    return kernels.Pairs(faces, props, shear, bonded, np.zeros((faces.shape[0], 2)), energy,
                         np.zeros((faces.shape[0], 4)))


def initial_state(scene: Scene, controls: Controls) -> State:
    pos = scene.pos0.copy()
    return State(pos=pos, vel=np.zeros_like(pos), pos_detect=pos.copy(), pairs=detect(scene, controls, None, pos),
                 acc=np.zeros(kernels.N_ACC), active=(~scene.driven).astype(np.int64),
                 calm=np.zeros(scene.driven.size, dtype=np.int64))


def chunk(scene: Scene, controls: Controls, state: State, n_steps: int, rate: float, target: float) -> Chunk:
    """Run up to ``n_steps`` steps (rebuilding the pair list as needed); returns the last kernel call's end.

    A kernel call runs at most ``controls.call_steps`` steps: Python takes Ctrl-C only between calls (a record
    of a huge run held 200 million steps, and Ctrl-C waited for minutes). A call's end changes no state, so
    the steps are the same however they are split."""
    wrench = np.zeros((scene.driven.size, scene.DOFS))
    left = n_steps
    while True:
        threads, steps = controls.threads.next_call(min(left, controls.call_steps))
        numba.set_num_threads(threads)
        started = time.perf_counter()
        report = state.advance_chunk(scene, controls, steps, rate, target, wrench)
        controls.threads.ran(threads, report.steps, time.perf_counter() - started)
        if not report.kinetic < UNSTABLE_KINETIC_ENERGY:  # also catches nan
            raise mf.SolveError(
                f"fdem: the time integration blew up (kinetic energy {report.kinetic:.3g} W x length after "
                f"{state.steps} steps, dt = {controls.dt:.3g} = {controls.dt / controls.dt_critical:.2f} dt_crit "
                "in scaled units); lower the option dt_safety"
            )
        state.steps += report.steps
        left -= report.steps
        if report.rebuild:
            state.rebuild_pairs(scene, controls)
        if left <= 0 or (target > 0 and state.acc[kernels.SETTLEMENT] >= target):
            return Chunk(report, wrench)


def gravity_phase(scene, controls, state, history, progress) -> None:
    """Apply the loads with the supports still until the unbalanced-force ratio drops below
    the rest tolerance (or for exactly ``gravity_time``).

    Masonry that does not stand (a block moves more than ``STAND_SHARE`` of a unit) stops the wait for rest at
    once: its damage is not the settlement's. A fixed ``gravity_time`` is a study of the fall itself (a block
    sliding down an incline), so it runs its whole time; either way no settlement follows."""
    if controls.gravity_time > 0:
        total = int(np.ceil(controls.gravity_time / controls.dt))
    else:  # a wall settles in a few sqrt(length / g); one that has not after 20 never will
        total = min(controls.max_steps, int(np.ceil(GRAVITY_TIME_LIMIT / controls.dt)))
    expected = controls.gravity_steps_expected
    warned = False
    while state.gravity_steps < total:
        n = min(controls.record_steps, total - state.gravity_steps)
        before = state.steps
        out = chunk(scene, controls, state, n, 0.0, 0.0)
        state.gravity_steps += state.steps - before
        history.add(GRAVITY_PHASE, state, out)
        state.gravity_motion = state.motions_from(scene, scene.pos0)
        if state.gravity_motion.max(initial=0.0) > STAND_SHARE * scene.unit_height:
            state.fell = True
            state.stop_reason = "did not stand under its own weight"
            if controls.gravity_time <= 0:
                return
        ramped = state.acc[kernels.TIME] >= controls.load_ramp
        if controls.gravity_time <= 0 and ramped and out.report.unbalanced < controls.rest_tolerance:
            state.stop_reason = "at rest"
            break
        if controls.gravity_time <= 0 and not warned and state.gravity_steps > OVERRUN * expected:
            warned = True
            LOG.warning("fdem: the gravity phase has run %d steps, %.0f times its estimate, and the masonry is not at "
                        "rest yet (unbalanced force ratio %.2e, rest at %g); it stops at %d steps, or sooner if a "
                        "block moves a tenth of a unit. Moving fastest: %s", state.gravity_steps,
                        state.gravity_steps / expected, out.report.unbalanced, controls.rest_tolerance, total,
                        fastest_blocks(scene, state))
        progress(0.05 * min(1.0, state.gravity_steps / max(total, 1)),
                 f"fdem: gravity, unbalanced force ratio {out.report.unbalanced:.2e}")
    else:
        if controls.gravity_time <= 0:
            raise mf.SolveError(
                f"fdem: the wall did not come to rest under its loads within {state.gravity_steps} steps "
                f"(unbalanced force ratio {history.table()['unbalanced'][-1]:.2e} > rest_tolerance "
                f"{controls.rest_tolerance:g}): it is not stable as built, or the integration is "
                f"(lower dt_safety); set gravity_time to run a fixed time instead. Moving fastest: "
                f"{fastest_blocks(scene, state)}"
            )
        if not state.fell:
            state.stop_reason = "gravity time reached"


def plateau_reached(history: History, controls: Controls, reference: float) -> bool:
    """The reaction varied less than ``plateau_tolerance * reference`` over the last
    ``plateau_window * target`` of settlement (and that much settlement came after the ramp)."""
    if controls.plateau_tolerance <= 0 or reference <= 0:
        return False
    rows = history.table()
    in_settlement = rows["phase"] == SETTLEMENT_PHASE
    settlement = rows["settlement"][in_settlement]
    reaction = rows["reaction"][in_settlement]
    if settlement.size < 3:
        return False
    window = controls.plateau_window * controls.target
    ramp_settlement = 0.5 * controls.rate * controls.ramp_time
    if settlement[-1] < window + ramp_settlement:
        return False
    recent = reaction[settlement >= settlement[-1] - window]
    return float(np.ptp(recent)) <= controls.plateau_tolerance * reference


def settlement_phase(scene, controls, state, history, progress) -> None:
    state.settlement_start = float(state.acc[kernels.TIME])
    reference = history.records[-1].row[3] if history.records else 0.0
    pending = sorted(controls.snapshots)
    while state.acc[kernels.SETTLEMENT] < controls.target:
        if state.steps >= controls.max_steps:
            state.stop_reason = "step limit"
            LOG.warning("fdem: settlement phase hit the step limit (%d)", controls.max_steps)
            return
        out = chunk(scene, controls, state, controls.record_steps, controls.rate, controls.target)
        history.add(SETTLEMENT_PHASE, state, out)
        settled = state.acc[kernels.SETTLEMENT]
        while pending and settled >= pending[0]:
            pending.pop(0)
            history.snapshots.append((settled, state.snapshot()))  # the first record past the request
        progress(0.05 + 0.95 * min(1.0, settled / controls.target),
                 f"fdem: settlement {settled / controls.target:.0%} of target, "
                 f"reaction {history.records[-1].row[3] / reference:.3f} R0" if reference > 0 else
                 f"fdem: settlement {settled / controls.target:.0%} of target")
        if plateau_reached(history, controls, reference):
            state.stop_reason = "reaction plateau"
            return
    state.stop_reason = "target settlement"


def block_motions(scene: Scene, pos: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """``(block,)``: every free block's motion from ``reference`` (centroid displacement plus rotation times the
    block radius), 0 for the driven ones."""
    moved = np.hypot(*(pos[:, :2] - reference[:, :2]).T) + np.abs(pos[:, 2] - reference[:, 2]) * scene.radius
    return np.where(scene.driven, 0.0, moved)


def largest_motion(scene: Scene, pos: np.ndarray, reference: np.ndarray) -> float:
    """Largest block motion from ``reference`` (:func:`block_motions`)."""
    return float(block_motions(scene, pos, reference).max(initial=0.0))


def fastest_blocks(scene: Scene, state: State, count: int = 3) -> str:
    """The ``count`` free blocks moving fastest, with where they are [m] and their speed [m/s], for a message."""
    speed = state.speeds(scene)
    length, time = scene.scales.length, scene.scales.time
    return ", ".join(f"block {b} at ({state.pos[b, 0] * length:.4g}, {state.pos[b, 1] * length:.4g}) m, "
                     f"{speed[b] * length / time:.3g} m/s" for b in np.argsort(-speed)[:count])


def hold(scene: Scene, controls: Controls, state: State, reference: np.ndarray, history: History,
         load_factor: float) -> tuple[bool, float]:
    """Run ``state`` until it is at rest after its load ramp (stable) or moves ``collapse_motion`` from
    ``reference`` or has not come to rest within ``search_trial_time`` (unstable); ``(stable, motion)``."""
    ramp_end = state.added_start + state.added_time
    limit = ramp_end + controls.search_trial_time
    while True:
        out = chunk(scene, controls, state, controls.record_steps, 0.0, 0.0)
        history.add(SEARCH_PHASE, state, out, load_factor)
        motion = largest_motion(scene, state.pos, reference)
        if motion > controls.collapse_motion:
            return False, motion
        now = state.acc[kernels.TIME]
        if now >= ramp_end and out.report.unbalanced < controls.rest_tolerance:
            return True, motion
        if now >= limit or state.steps >= controls.max_steps:
            return False, motion


def search_phase(scene: Scene, controls: Controls, state: State, history: History, progress) -> None:
    """The load-factor search of the module docstring; ``state`` ends as the last unstable trial
    (the last stable one if none was), ``state.trials`` lists every trial."""
    try:
        lower, upper, unstable = _bisect(scene, controls, state, history, progress)
    except KeyboardInterrupt:  # keep the last state at rest and the trials so far
        _become(state, state.last_stable)
        raise
    final = unstable if unstable is not None else state.last_stable
    _become(state, final)
    state.collapse_bracket = (lower, upper)


def _become(state: State, other: State) -> None:
    """``state`` takes the fields of ``other`` but keeps its own trials, stop reason and bracket."""
    keep = {name: getattr(state, name) for name in ("trials", "stop_reason", "collapse_bracket")}
    state.__dict__.update({k: v for k, v in other.__dict__.items() if k not in keep})


def _bisect(scene, controls, state, history, progress):
    """The trials: ``(largest stable, smallest unstable, its state)`` (None, None if none was unstable)."""
    base = state.load.copy()
    lower, upper, unstable = 0.0, None, None
    stable = state.last_stable = copy.deepcopy(state)
    trial = controls.search_first
    while upper is None or upper - lower > controls.search_tolerance:
        if trial > controls.search_limit:
            state.stop_reason = f"stable up to the search limit {controls.search_limit:g}"
            break
        attempt = copy.deepcopy(stable)
        attempt.set_loads(scene, base + lower * scene.live, (trial - lower) * scene.live,
                          float(attempt.acc[kernels.TIME]), controls.search_step_time)
        is_stable, motion = hold(scene, controls, attempt, stable.pos, history, trial)
        state.trials.append((trial, is_stable, motion))
        if is_stable:
            lower, stable = trial, attempt
            stable.set_loads(scene, base + trial * scene.live)
            state.last_stable = stable
        else:
            upper, unstable = trial, attempt
        state.steps = attempt.steps
        state.collapse_bracket = (lower, upper)
        trial = 2.0 * trial if upper is None else 0.5 * (lower + upper)
        bracket = "" if upper is None else f", unstable at {upper:.4g}"
        progress(0.05 + 0.9 * min(1.0, len(state.trials) / 16), f"fdem: stable at load factor {lower:.4g}{bracket}")
    else:
        state.stop_reason = "collapse bracketed"
    return lower, upper, unstable


def run(scene, controls: Controls, state: State, load: np.ndarray, progress,
        opening: Callable[..., mf.Cracks] | None = None) -> History:
    """Gravity, then settlement, from ``state`` (rigid or deformable, 2D or 3D); returns the history
    (``opening``: :attr:`History.opening`, of the state's :meth:`State.snapshot`).

    A KeyboardInterrupt keeps what was computed (``state.interrupted``, the state
    reached evaluated as a last record); one before the first record propagates.
    """
    history = History(scene.direction, opening=opening, vertical=scene.VERTICAL)
    state.set_loads(scene, load)
    try:
        gravity_phase(scene, controls, state, history, progress)
        if state.fell:
            pass  # its damage is not the settlement's: nothing more to run (the result says so)
        elif controls.search:
            search_phase(scene, controls, state, history, progress)
        elif controls.target > 0 and scene.moving.any():
            settlement_phase(scene, controls, state, history, progress)
    except KeyboardInterrupt:
        if not history.records:
            raise
        state.interrupted = True
        state.stop_reason = "interrupted"
        out = chunk(scene, controls, state, 0, 0.0, 0.0)  # evaluate the state reached
        phase = SEARCH_PHASE if state.trials else SETTLEMENT_PHASE if state.settlement_start > 0 else GRAVITY_PHASE
        history.add(phase, state, out, state.collapse_bracket[0] if state.collapse_bracket else 0.0)
    return history
