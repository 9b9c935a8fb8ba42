"""The threads of the kernel calls, chosen by how fast each count runs on this machine now.

Numba's parallel loops (its OpenMP layer) share each step's contact pass between threads that spin at the
step's barriers. Facade 3, 2-core machine, 2026-11-27: quiet, two threads ran 1.2x faster than one; beside
two busy processes 1.3x slower; on a drawn 3,105-unit facade at load 4-5 about 20x slower, every barrier
waiting for a core another process held. Letting the threads sleep at the barriers
(``OMP_WAIT_POLICY=passive``) cost 4x on the quiet machine (a wake-up each parallel region). No count is
right everywhere, and a machine's load changes during a long run, so the count is measured: the run times
its kernel calls on each count, keeps the faster, and tries the others again for a short call every
:data:`PROBE_SECONDS` of running. The trajectory does not depend on the count, bit for bit (the kernels sum
in face order), so switching changes no result.
"""
from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import masonryfw.plugin_api as mfp

#: Below this many blocks one thread: two threads add ~20 us a step of start-up and save ~0.145 us a block
#: (whole processes in alternating pairs: Test 12C, 72 blocks, 0.86x on two threads; Facade 3, 480 blocks, 1.59x).
PARALLEL_MIN_BLOCKS = 300
#: Seconds of running between two tries of the counts not in use.
PROBE_SECONDS = 10.0
#: Seconds of calls on one count that make one measure of its speed.
MEASURE_SECONDS = 0.02
#: A try of another count runs calls of about this long at its own last pace; its first call is one step. A
#: busy machine was seen to stretch a step of two threads to 32 ms (Facade 3, 0.12 ms on one): a try costs
#: about two such steps.
TRY_SECONDS = 0.005
#: Seconds of kernel calls over which a count's measured speed is averaged.
WINDOW_SECONDS = 1.0
def expected_count(available: int, cores: int, load: float) -> int:
    """The count the run will most likely settle on: every thread numba has while the machine has cores for
    them, else the free cores (at least one)."""
    return int(min(available, max(1, round(mfp.free_cores(cores, load)))))


@dataclass
class Threads:
    """The count of threads of each kernel call: fixed (one count) or chosen by measurement among ``counts``.

    A count's speed is measured over consecutive calls until they have run :data:`MEASURE_SECONDS` (calls are
    often short: a record every few dozen steps); the first call on a count is left out (it starts the count's
    threads, or loads the compiled kernels)."""

    counts: tuple[int, ...]
    current: int
    seconds_per_step: dict[int, float] = field(default_factory=dict)
    measured_at: dict[int, float] = field(default_factory=dict)
    steps_on: dict[int, int] = field(default_factory=dict)
    pending: dict[int, tuple[int, float]] = field(default_factory=dict)  # steps and seconds not yet a measure
    pace: dict[int, float] = field(default_factory=dict)  # seconds a step of the last call on each count
    clock: Callable[[], float] = time.perf_counter

    @classmethod
    def fixed(cls, count: int) -> Threads:
        return cls((count,), count)

    @classmethod
    def measured(cls, available: int, cores: int, load: float) -> Threads:
        """Counts from one to ``available``'s, starting from the :func:`expected_count`."""
        first = expected_count(available, cores, load)
        return cls(tuple(sorted({1, first, available})), first)

    @classmethod
    def chosen(cls, option: int | None, blocks: int, available: int) -> Threads:
        """The ``threads`` option's count (at most numba's ``available``); auto: one below
        :data:`PARALLEL_MIN_BLOCKS`, else measured."""
        if option is not None:
            return cls.fixed(min(option, available))
        if blocks < PARALLEL_MIN_BLOCKS:
            return cls.fixed(1)
        return cls.measured(available, mfp.cores(), mfp.machine_load())

    def next_call(self, steps: int) -> tuple[int, int]:
        """``(threads, steps)`` of the next kernel call of up to ``steps``: a stale count gets short tries (one
        step first; then as many as its own last call's pace runs in :data:`TRY_SECONDS`)."""
        if self.steps_on and self.current in self.seconds_per_step:
            now = self.clock()
            for count in self.counts:
                if count != self.current and now - self.measured_at.get(count, -PROBE_SECONDS) >= PROBE_SECONDS:
                    return count, min(steps, max(1, int(TRY_SECONDS / self.pace.get(count, math.inf))))
        return self.current, steps

    def ran(self, count: int, steps: int, seconds: float) -> None:
        """A call of ``steps`` steps on ``count`` threads took ``seconds``; once measured, the faster count
        becomes current."""
        warming = count not in self.steps_on
        self.steps_on[count] = self.steps_on.get(count, 0) + steps
        if steps:
            self.pace[count] = seconds / steps
        if warming or len(self.counts) == 1:
            return
        steps_so_far, seconds_so_far = self.pending.get(count, (0, 0.0))
        steps_so_far, seconds_so_far = steps_so_far + steps, seconds_so_far + seconds
        if seconds_so_far < MEASURE_SECONDS or steps_so_far == 0:
            self.pending[count] = (steps_so_far, seconds_so_far)
            return
        self.pending.pop(count, None)
        observed = seconds_so_far / steps_so_far
        if count == self.current and count in self.seconds_per_step:  # a try replaces what is stale
            weight = min(1.0, seconds_so_far / WINDOW_SECONDS)
            observed = (1.0 - weight) * self.seconds_per_step[count] + weight * observed
        self.seconds_per_step[count] = observed
        self.measured_at[count] = self.clock()
        if self.current in self.seconds_per_step:
            self.current = min(self.seconds_per_step, key=self.seconds_per_step.__getitem__)

    def most_used(self) -> int:
        """The count that ran the most steps (the current one before any step)."""
        return max(self.steps_on, key=self.steps_on.__getitem__) if self.steps_on else self.current
