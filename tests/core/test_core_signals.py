"""What a signal does to a write, in this process: held while the file is written, dropped once the command's
outcome is settled (its last claimed output in place). The signal is raised from inside the write itself, so
where it lands is known exactly; the whole command is tested from outside in test_core_faults.py."""
from __future__ import annotations

import signal

import pytest

import masonryfw.plugin_api as mfp
from masonryfw.runtime import signals


@pytest.fixture
def command_line():
    """The command line's handlers installed in this process for one test, then this process's own restored."""
    before = {signum: signal.getsignal(signum) for signum in signals.DEFERRED}
    signal.signal(signal.SIGINT, signal.default_int_handler)  # as a terminal leaves it (a background job ignores it)
    signals.install()
    yield
    signals._Command.answering = signals._Command.settled = False
    for signum, handler in before.items():
        signal.signal(signum, handler)


def _writing(text: str, signum: int | None = None):
    def write(temporary):
        temporary.write_text(text)
        if signum is not None:
            signal.raise_signal(signum)  # taken at once by Python: inside the write
    return write


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_inside_a_write_completes_the_file_then_interrupts(tmp_path, command_line, signum):
    target = mfp.check_output_path(tmp_path / "a.txt")
    with pytest.raises(signals.WriteInterrupted) as raised:
        mfp.write_atomically({target: _writing("whole", signum)})
    assert raised.value.signum == signum and raised.value.path == target
    assert target.read_text() == "whole" and sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]


def test_the_last_claimed_output_settles_the_outcome_and_a_signal_after_it_changes_nothing(tmp_path, command_line):
    first = mfp.check_output_path(tmp_path / "first.txt")
    second = mfp.check_output_path(tmp_path / "second.txt")  # claimed before the work, as a command does
    mfp.write_atomically({first: _writing("1")})
    assert not signals._Command.settled  # the second is still to come: a signal now interrupts
    with pytest.raises(KeyboardInterrupt):
        signal.raise_signal(signal.SIGINT)
    mfp.write_atomically({second: _writing("2")})
    assert signals._Command.settled
    signal.raise_signal(signal.SIGINT)  # dropped: the command says what it did and exits with its own status
    signal.raise_signal(signal.SIGTERM)
    assert first.read_text() == "1" and second.read_text() == "2"


def test_outside_the_command_line_nothing_is_ever_dropped(tmp_path):
    """A script's Ctrl-C after its last write still interrupts it."""
    inherited = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        target = mfp.check_output_path(tmp_path / "a.txt")
        mfp.write_atomically({target: _writing("whole")})
        assert not signals._Command.settled
        with pytest.raises(KeyboardInterrupt):
            signal.raise_signal(signal.SIGINT)
    finally:
        signal.signal(signal.SIGINT, inherited)
