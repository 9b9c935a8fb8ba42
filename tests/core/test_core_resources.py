"""Memory limits and the refusal of a run that cannot fit (masonryfw.runtime.resources)."""
from __future__ import annotations

import re

import pytest

import masonryfw as mf
import masonryfw.plugin_api as mfp
from masonryfw.runtime.resources import available_memory, parse_bytes, require_memory


@pytest.mark.parametrize("text, value", [("1024", 1024.0), ("4GiB", 4 * 2**30), ("512 MiB", 512 * 2**20),
                                         ("2GB", 2e9), ("1.5e3kb", 1.5e6)])
def test_sizes_are_read_with_their_units(text, value):
    assert parse_bytes(text) == value


@pytest.mark.parametrize("text", ["lots", "1.2.3", "1e+-", "4 GB of it", ""])
def test_a_size_that_is_not_one_is_named(text):
    with pytest.raises(mf.SolveError, match=re.escape(f"MASONRYFW_MEMORY_LIMIT={text!r} is not a size")):
        parse_bytes(text)


def test_the_variable_overrides_the_system(monkeypatch):
    monkeypatch.delenv("MASONRYFW_MEMORY_LIMIT", raising=False)
    system = available_memory()
    assert 0 < system
    monkeypatch.setenv("MASONRYFW_MEMORY_LIMIT", "3GiB")
    assert available_memory() == 3 * 2**30


def test_a_run_over_the_limit_is_refused_with_the_advice(monkeypatch):
    monkeypatch.setenv("MASONRYFW_MEMORY_LIMIT", "1GiB")
    require_memory("x", 2**30, "b")  # exactly fits
    with pytest.raises(mf.SolveError, match=r"solver x: this run needs about 2.0 GiB .* 1.0 GiB is available "
                                            r".*; to make it smaller: use less"):
        require_memory("x", 2**31, "b", "use less")


def test_an_interruptible_call_returns_its_value_and_raises_its_error():
    assert mfp.interruptible(lambda: 42) == 42
    with pytest.raises(ZeroDivisionError):
        mfp.interruptible(lambda: 1 / 0)


def test_ctrl_c_reaches_the_caller_during_a_long_call_that_releases_the_gil():
    """time.sleep stands in for a solver's compiled loop that releases the GIL (Clarabel's)."""
    import _thread
    import signal
    import threading
    import time

    # Python's own handler, whatever this process inherited (a background job ignores SIGINT)
    inherited = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        ended = []
        timer = threading.Timer(0.3, _thread.interrupt_main)
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            mfp.interruptible(lambda: (time.sleep(60), ended.append(True)))
        assert ended == []  # reached the caller while the call still ran (no clock: the call says when it ends)
        timer.join()
    finally:
        signal.signal(signal.SIGINT, inherited)
