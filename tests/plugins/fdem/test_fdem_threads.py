"""The thread count of fdem's kernel calls is measured as the run goes (threads.py): it follows the faster
count, tries the other again, keeps its tries short on a count that stalls, and changes no result."""
from __future__ import annotations

import numpy as np
import pytest

import masonryfw as mf
from masonryfw_fdem import threads
from masonryfw_fdem.threads import Threads


class Clock:
    """A clock the test moves: each call's seconds are added to it."""

    def __init__(self):
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def run(choice: Threads, clock: Clock, seconds_per_step, calls: int, steps: int = 1000) -> list[tuple[int, int]]:
    """``calls`` kernel calls of up to ``steps`` where a step on ``count`` threads costs
    ``seconds_per_step(count, time)``; the (count, steps) of each."""
    done = []
    for _ in range(calls):
        count, n = choice.next_call(steps)
        seconds = n * seconds_per_step(count, clock.now)
        clock.now += seconds
        choice.ran(count, n, seconds)
        done.append((count, n))
    return done


def measured(first: int, clock: Clock) -> Threads:
    choice = Threads.measured(available=2, cores=2, load=0.0 if first == 2 else 1.5)
    choice.clock = clock
    return choice


@pytest.mark.parametrize("first", [1, 2])
def test_the_faster_count_is_kept_whichever_it_started_on(first):
    clock = Clock()
    choice = measured(first, clock)
    assert choice.current == first
    done = run(choice, clock, lambda count, now: {1: 1e-4, 2: 6e-5}[count], calls=40)
    assert choice.current == 2
    assert sum(n for count, n in done[-20:] if count == 1) == 0
    clock2 = Clock()
    busy = measured(first, clock2)
    run(busy, clock2, lambda count, now: {1: 1.5e-4, 2: 3e-3}[count], calls=40)
    assert busy.current == 1
    assert busy.most_used() == 1


def test_a_machine_that_gets_busy_mid_run_is_followed_and_one_that_gets_quiet_again():
    """Two threads are faster until another job starts at 30 s and stops at 90 s; within two tries of it
    the run is on one thread, then back on two."""
    clock = Clock()
    choice = measured(2, clock)

    def pace(count, now):
        busy = 30.0 <= now < 90.0
        return {1: 1.5e-4, 2: 4e-3}[count] if busy else {1: 1e-4, 2: 6e-5}[count]

    counts = []
    while clock.now < 150.0:
        count, _ = run(choice, clock, pace, calls=1)[0]
        counts.append((clock.now, count, choice.current))
    on_one = [now for now, _, current in counts if current == 1]
    assert 30.0 <= min(on_one) < 30.0 + 2 * threads.PROBE_SECONDS
    assert 90.0 <= max(on_one) < 90.0 + 2 * threads.PROBE_SECONDS
    assert all(current == 2 for now, _, current in counts if now > 90.0 + 2 * threads.PROBE_SECONDS)


def test_a_try_of_a_stalling_count_costs_a_few_of_its_steps():
    """Two threads stalled to 32 ms a step (seen beside other jobs): the first try is one step, the next sized
    to its own pace, so a try costs well under a second."""
    clock = Clock()
    choice = measured(1, clock)
    spent: dict[int, float] = {1: 0.0, 2: 0.0}

    def pace(count, now):
        return {1: 1.2e-4, 2: 0.032}[count]

    for count, n in run(choice, clock, pace, calls=200):
        spent[count] += n * pace(count, 0)
    tries = 1 + int(clock.now // threads.PROBE_SECONDS)
    assert spent[2] <= tries * 0.1
    assert choice.current == 1


def test_a_fixed_count_is_kept_and_small_walls_run_on_one_thread():
    assert Threads.chosen(2, 5000, available=2).counts == (2,)
    assert Threads.chosen(4, 5000, available=2).counts == (2,)
    assert Threads.chosen(None, threads.PARALLEL_MIN_BLOCKS - 1, available=2).counts == (1,)
    assert Threads.chosen(None, threads.PARALLEL_MIN_BLOCKS, available=2).counts == (1, 2)


def test_the_expected_count_and_the_share_of_a_core_follow_the_load():
    assert threads.expected_count(2, cores=2, load=0.2) == 2
    assert threads.expected_count(2, cores=2, load=1.2) == 1
    assert threads.expected_count(2, cores=2, load=4.0) == 1


def test_switching_counts_at_every_call_changes_no_bit(monkeypatch):
    """Calls of 37 steps on one thread and two in turn on Facade 3 (480 blocks): the trajectory is the one of a
    single thread, bit for bit."""
    model = mf.open_model("facade-3")
    options = {"settlement": 5e-4, "plateau_tolerance": 0.0}
    one = mf.solve(model, "fdem", options | {"threads": 1})
    calls = iter(range(10**9))
    monkeypatch.setattr(Threads, "next_call", lambda self, steps: (1 + next(calls) % 2, min(steps, 37)))
    switching = mf.solve(model, "fdem", options)
    steps = dict(pair.split(": ") for pair in switching.attrs["fdem_thread_steps"].split(", "))
    assert set(steps) == {"1", "2"} and min(int(v) for v in steps.values()) > 1000
    assert np.array_equal(one.block_displacement.values, switching.block_displacement.values)
    assert np.array_equal(one.step_reaction.values, switching.step_reaction.values)
    assert one.attrs["fdem_steps"] == switching.attrs["fdem_steps"]
