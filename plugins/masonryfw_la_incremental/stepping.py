"""The increments: limit state of the current configuration, blocks moved by its mechanism, contacts again.

Each increment solves la's programme on the current configuration (:func:`masonryfw_la.limit_state`:
associative, then by default non-associative with the associative state's normal forces), moves every block along its mechanism by the exact rigid motion of
a constant twist (:func:`.motion.screw`) and finds the contacts of the moved configuration. The size
is adaptive: the fastest point of any block moves ``step`` times the median unit height; a step whose
blocks overlap by more than the contact gap (or than before it) is halved; while the mechanism changes so little
over a step that following its first mechanism moved no point a gap from the trapezoid rule's path, the steps
grow up to :data:`MAX_GROWTH` times (a grown step that fails is taken again at ``step``). A step after which the configuration cannot
carry its dead load (the programme is unbounded) brackets the collapse: the bracket is halved until
the fastest point would move less than :data:`COLLAPSE_RESOLUTION` of a step, and the last
configuration that stands is the capacity. A failure seen from one configuration is forgotten once a
shorter step from it stands: a long step can lose a contact the wall needs (a block stepping off its
support's corner) where shorter ones do not, so only a configuration that falls within the resolution
of the last one that stands is a collapse. Settlement runs are driven by the settlement parameter t
(the mechanism is per unit t); runs with a live load and no moving support by the largest block
translation (a capacity curve: the multiplier of the moved configuration against it), and collapse
where the multiplier falls to zero.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw_la import DeadLoadNotCarried, LimitState, LiveLoadUnbounded, Wall, falling_motion, limit_state

from . import motion
from .configuration import Reference, intact_joints, wall_at

#: The collapse is bracketed to this share of a step's largest motion.
COLLAPSE_RESOLUTION = 1e-2
#: A step is halved at most this many times in a row before the run stops (the LP keeps failing).
MAX_HALVINGS = 30
#: A part that falls lands within this many median unit heights (its fastest point's travel) more than the ground
#: has moved, or the wall collapses.
LANDING_DISTANCE = 0.5
#: A fall moves its fastest point this many steps at a time (halved where it would go into a block: it lands).
FALL_STEPS = 5.0
#: While the mechanism changes little over a step, the next steps grow by 1.5 up to this many times ``step``.
MAX_GROWTH = 8.0
#: "Little": following the step's first mechanism put no point further than this many gaps from where the mean of
#: its first and last mechanisms would have (half the step times the largest change of a point's velocity: the
#: error estimate of the trapezoid rule against the forward step taken).
STEADY_DRIFT = 1.0


class Controls(NamedTuple):
    """What the user set (options.py), in the units of the run."""

    target: float  # settlement parameter [m] or largest translation [m] to stop at
    step: float  # the fastest point's motion per increment [m]
    max_increments: int
    solver: str
    record_spacing: float  # the largest change of the parameter between two records (0: no limit)
    tolerance: float
    flow: str  # "nonassociative": joints slide without opening; "associative": la's dilatant joints


class Configuration(NamedTuple):
    """One configuration that stands: its parameter, block poses and limit state."""

    t: float
    pose: np.ndarray  # (block, 3) finite displacement of the centroid and rotation
    wall: Wall  # its contacts as la's interfaces
    state: LimitState
    overlap: float  # the deepest vertex inside another block [m]
    intact: np.ndarray  # (model interface,) the joints whose cohesion and tensile strength hold


class Outcome(NamedTuple):
    """How the run ended."""

    collapsed: bool
    capacity: float | None  # the parameter at collapse (the last configuration that stands)
    reason: str
    interrupted: bool


def settlement_driven(ref: Reference) -> bool:
    return bool(ref.wall.moving.any())


def pose_at(ref: Reference, pose: np.ndarray, mechanism: np.ndarray, dt: float, t_support: float) -> np.ndarray:
    """The blocks moved by ``mechanism`` over ``dt``; the moving supports placed at ``t_support`` from the start."""
    moved = pose + motion.screw(mechanism, dt)
    if settlement_driven(ref):
        moving = ref.wall.moving
        moved[moving] = motion.screw(ref.wall.direction[moving], t_support)
    held = ~ref.wall.moving & (ref.ground | ref.wall.fixed.all(axis=1))
    moved[held] = pose[held]
    return moved


#: A step may deepen an overlap that was already past the gap by this share of the gap (second order: the
#: contacts hold the first).
OVERLAP_GROWTH = 0.1


def allowed_overlap(ref: Reference, before: float) -> float:
    """How deep a step may leave a vertex in another block: the gap, or a little more than what a step too
    short to split had already left (a step is judged by what it adds)."""
    return ref.gap if before <= ref.gap else before + OVERLAP_GROWTH * ref.gap


def shorter(scale: float) -> float:
    """The step's share after a step of ``scale`` failed: half of it, or the step itself after a grown one."""
    return 1.0 if scale > 1.0 else 0.5 * scale


def drift(ref: Reference, before: np.ndarray, after: np.ndarray, dt: float) -> float:
    """How far a step of ``dt`` along ``before`` put a point from where the mean of ``before`` and ``after`` (the
    mechanisms at its two ends) would have [m]."""
    return 0.5 * dt * fastest_point(ref, after - before)


def fastest_point(ref: Reference, mechanism: np.ndarray) -> float:
    """The largest velocity of any point of a moving masonry block per unit of the parameter."""
    masonry = ~ref.ground
    speed = np.hypot(mechanism[:, 0], mechanism[:, 1]) + np.abs(mechanism[:, 2]) * ref.radius
    return float(speed[masonry].max(initial=0.0))


class Placed(NamedTuple):
    """The blocks at a pose: which bonds hold there and the contacts found (found once per pose)."""

    pose: np.ndarray
    intact: np.ndarray
    wall: Wall
    overlap: float


def placed(ref: Reference, pose: np.ndarray, intact: np.ndarray) -> Placed:
    """The wall at ``pose``; a joint ``intact`` before that opened or slid past the gap loses its bond here."""
    intact = intact_joints(ref, pose, intact)
    wall, contacts = wall_at(ref, pose, intact)
    return Placed(pose, intact, wall, contacts.overlap)


def solved(ref: Reference, at: Placed, controls: Controls, t: float) -> Configuration:
    """The configuration at a placed pose: its limit state (module docstring).

    Non-associative joints (the default) take the shear capacity of the normal forces of the configuration's
    own associative state: the first two LPs of la's non-associative sequence. :class:`DeadLoadNotCarried`
    when the configuration cannot carry its dead load.
    """
    state = limit_state(at.wall, ref.scales, controls.solver, controls.tolerance)
    if controls.flow == "nonassociative":
        state = limit_state(at.wall, ref.scales, controls.solver, controls.tolerance, state.normal)
    return Configuration(t, at.pose, at.wall, state, at.overlap, at.intact)


def bonded_joints(ref: Reference) -> np.ndarray:
    """The model's joints with cohesion or tensile strength: intact at the start."""
    return (ref.wall.cohesion > 0) | (ref.wall.tensile_strength > 0)


def first_configuration(ref: Reference, controls: Controls) -> Configuration:
    pose = np.zeros((ref.n_block, 3))
    try:
        return solved(ref, placed(ref, pose, bonded_joints(ref)), controls, 0.0)
    except DeadLoadNotCarried as error:
        raise mf.SolveError(f"la-incremental: the wall does not stand under its dead load before it moves ({error})") \
            from error


def fall(ref: Reference, controls: Controls, pose: np.ndarray, t: float,
         intact: np.ndarray) -> Configuration | Outcome:
    """Let the part that cannot stand at ``pose`` fall, the supports held, until it lands (a configuration
    that stands: a block dropping onto the one that settled beneath it). When it has not landed after its
    fastest point fell :data:`LANDING_DISTANCE` unit heights further than the ground has moved (a block can drop
    into the gap a settlement opened under it, not through the ground), or cannot move along its fall without
    going into another block, the run ends: the wall collapses in the first case; in the second a contact
    the programme does not see (a corner on a corner) holds the part, and no capacity is claimed."""
    travelled, shrink = 0.0, 1.0
    reach = LANDING_DISTANCE * ref.unit_height + ground_motion(ref, t)
    stride = FALL_STEPS * controls.step
    here = placed(ref, pose, intact)
    falling = falling_motion(here.wall, ref.scales)
    blocks = moving_blocks(falling)
    for _ in range(int(20 * reach / stride) + 100):  # room for the halvings where it touches down
        speed = fastest_point(ref, falling)
        if speed <= 0:  # carried with associative joints, not with joints that slide without opening
            break
        if travelled >= reach:
            return Outcome(True, t, f"{falling_text(blocks)} fell {travelled:.3g} m without landing", False)
        moved = placed(ref, pose_at(ref, here.pose, falling, shrink * stride / speed, t), here.intact)
        if moved.overlap > allowed_overlap(ref, here.overlap):
            if shrink < COLLAPSE_RESOLUTION:
                return Outcome(False, None, f"at {t:.6g} m {falling_text(blocks)} cannot stand in the programme and "
                                            "cannot move without going into another block: a contact the "
                                            "programme does not see (a corner on a corner) holds it", False)
            shrink *= 0.5
            continue
        here, travelled = moved, travelled + shrink * stride
        shrink = min(1.0, 1.5 * shrink)
        falling = falling_motion(here.wall, ref.scales)
        if falling.any():
            blocks = moving_blocks(falling)
            continue
        try:  # landed: the dead load is carried (falling_motion's programme is the unboundedness test)
            return solved(ref, here, controls, t)
        except DeadLoadNotCarried:
            break
        except mf.SolveError as error:
            return Outcome(False, None, f"the programme failed at {t:.6g} m while {falling_text(blocks)} fell: "
                                        f"{error}", False)
    return Outcome(False, None, f"at {t:.6g} m {falling_text(blocks) if blocks.size else 'a part'} kept falling in "
                                f"short steps, {travelled:.3g} m in all, neither landing nor falling "
                                f"{reach:.3g} m: no capacity is claimed", False)


def moving_blocks(motion: np.ndarray) -> np.ndarray:
    """The blocks a motion moves (beyond round-off of its largest component)."""
    return np.flatnonzero(np.abs(motion).max(axis=1) > 1e-6 * np.abs(motion).max(initial=0.0))


def ground_motion(ref: Reference, t: float) -> float:
    """How far the ground has settled at ``t`` [m]: the settlement parameter (0 under a live load)."""
    return abs(t) if settlement_driven(ref) else 0.0


def falling_text(blocks: np.ndarray) -> str:
    return "no block" if blocks.size == 0 else f"block {blocks[0]}" if blocks.size == 1 else f"{blocks.size} blocks ({mfp.listed(blocks)})"


def run(ref: Reference, controls: Controls, record, progress) -> Outcome:
    """Follow the wall from the model's configuration (module docstring); ``record(configuration)`` for each."""
    current = first_configuration(ref, controls)
    record(current)
    driven = settlement_driven(ref)
    failing: tuple[float, np.ndarray] | None = None  # a parameter (and pose) that does not stand: bracketed
    scale = 1.0  # the share of the step the last overlaps or failed solves allow, or its growth while steady
    halvings = 0
    try:
        for _ in range(controls.max_increments):
            if not driven and current.state.alpha <= 0.0:
                return Outcome(True, current.t, "the multiplier of the moved configuration fell to zero", False)
            if current.t >= controls.target * (1 - 1e-12):
                return Outcome(False, None, f"reached the target {controls.target:.6g} m before collapse", False)
            speed = fastest_point(ref, current.state.motion)
            if speed <= 0:
                return Outcome(False, None, "no block moves: the mechanism is the supports' motion alone", False)
            resolution = COLLAPSE_RESOLUTION * controls.step / speed
            if failing is not None and failing[0] - current.t <= resolution:
                landed = fall(ref, controls, failing[1], failing[0], current.intact)
                if isinstance(landed, Outcome):
                    return landed._replace(capacity=current.t) if landed.collapsed else landed
                current, failing = landed, None
                record(current)
                continue
            dt = min(scale * controls.step / speed, controls.target - current.t, controls.record_spacing or np.inf)
            if failing is not None:
                dt = min(dt, 0.5 * (failing[0] - current.t))
            pose = pose_at(ref, current.pose, current.state.motion, dt, current.t + dt)
            try:
                trial = solved(ref, placed(ref, pose, current.intact), controls, current.t + dt)
            except DeadLoadNotCarried:
                if scale <= 1.0:  # a grown step that fails is taken again at the step, not bracketed (a guess)
                    failing = (current.t + dt, pose)  # from this configuration: a fall once it is this close
                scale = shorter(scale)
                continue
            except LiveLoadUnbounded:
                return Outcome(False, None, f"at {current.t + dt:.6g} m the wall stands free of the moving supports: "
                                            "further settlement does not load it", False)
            except mf.SolveError as error:
                halvings += 1
                if halvings > MAX_HALVINGS or dt <= resolution:
                    return Outcome(False, None, f"the programme failed at {current.t + dt:.6g} m: {error}", False)
                scale = shorter(scale)
                continue
            if trial.overlap > allowed_overlap(ref, current.overlap) and dt > resolution:
                scale = shorter(scale)  # the step was too long for its contacts: a vertex went into a block
                continue
            halvings = 0
            steady = drift(ref, current.state.motion, trial.state.motion, dt) <= STEADY_DRIFT * ref.gap
            scale = min(MAX_GROWTH if steady else 1.0, 1.5 * scale)
            failing = None  # a failure seen from the last configuration may be the long step's, not the wall's
            current = trial
            record(current)
            progress(min(current.t / controls.target, 1.0), f"la-incremental: {current.t:.4g} m, "
                                                            f"{current.wall.n_interface} contacts")
        return Outcome(False, None, f"stopped after {controls.max_increments} increments at {current.t:.6g} m", False)
    except KeyboardInterrupt:
        return Outcome(False, None, f"interrupted at {current.t:.6g} m (Ctrl-C)", True)
