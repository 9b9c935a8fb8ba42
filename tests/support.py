"""What the tests share to run ``python -m masonryfw`` as a user would and look at it from outside: its exit
status and stderr (:func:`cli`, :func:`refused`), its peak memory (:func:`peak_memory`), the hidden files it
leaves (:func:`hidden`), a command signalled when its stderr says a phase has begun (:class:`Command`), and a
process held still (:func:`stopped`) while a test looks at what it is doing and signals it there.

No test here depends on winning a race against the scheduler: a signal is sent at a point the test has seen
the process reach (a line on its stderr), while the process is stopped where the test has looked at it (its
open files, the files in its folder), never after a delay."""
from __future__ import annotations

import os
import re
import select
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


def cli(args, cwd, env=None, timeout=120) -> subprocess.CompletedProcess:
    """``python -m masonryfw ARGS`` in ``cwd``, run to its end."""
    return subprocess.run([sys.executable, "-m", "masonryfw", *map(str, args)], cwd=cwd, capture_output=True,
                          text=True, timeout=timeout, env={**os.environ, **(env or {})})


def refused(done: subprocess.CompletedProcess, *words: str) -> None:
    """Exit 1, a one-line ``error:`` message holding ``words``, no traceback."""
    assert done.returncode == 1, (done.returncode, done.stderr[-2000:])
    assert "Traceback" not in done.stderr and done.stderr.startswith("error: "), done.stderr[-2000:]
    for word in words:
        assert word in done.stderr, (word, done.stderr)


def peak_memory(args, cwd, env=None, timeout=120) -> tuple[subprocess.CompletedProcess, float]:
    """Run the CLI under a watcher process; return the result and the CLI's peak resident memory [bytes]."""
    watcher = ("import resource, subprocess, sys\n"
               "done = subprocess.run(sys.argv[1:])\n"
               "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, file=sys.stderr)\n"
               "sys.exit(done.returncode)\n")
    done = subprocess.run([sys.executable, "-c", watcher, sys.executable, "-m", "masonryfw", *map(str, args)],
                          cwd=cwd, capture_output=True, text=True, timeout=timeout, env={**os.environ, **(env or {})})
    *message, peak = done.stderr.rstrip("\n").splitlines()
    done.stderr = "\n".join(message) + "\n"
    return done, float(peak) * 1024


def hidden(folder: Path) -> list[str]:
    """Temporary and lock files left in ``folder``."""
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


class Command:
    """``python -m masonryfw ARGS`` started in ``cwd`` as a user's terminal would (SIGINT at its default: a
    process started in the background inherits it ignored), its stderr read as it comes."""

    def __init__(self, args, cwd, env=None, python=()):
        self.process = subprocess.Popen(
            [sys.executable, *python, "-m", "masonryfw", *map(str, args)], cwd=cwd, text=True,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, env={**os.environ, **(env or {})},
            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
        self.seen = ""

    def wait_for(self, pattern: str, timeout: float = 240.0) -> str:
        """Read stderr until ``pattern`` (a regular expression) appears in it; what was read."""
        deadline, fd = time.monotonic() + timeout, self.process.stderr.fileno()
        while time.monotonic() < deadline:
            if re.search(pattern, self.seen):
                return self.seen
            if select.select([fd], [], [], 1.0)[0]:
                chunk = os.read(fd, 65536).decode(errors="replace")
                if not chunk:
                    break
                self.seen += chunk
        raise AssertionError(f"never saw {pattern!r} in: {self.seen[-800:]}")

    def signal(self, signum: int, timeout: float = 120.0) -> tuple[int, str, float]:
        """Send ``signum``; the exit status, the whole stderr and the seconds the process took to end."""
        sent = time.monotonic()
        self.process.send_signal(signum)
        _, rest = self.process.communicate(timeout=timeout)
        return self.process.returncode, self.seen + rest, time.monotonic() - sent

    def stop(self) -> None:
        """Kill it if still running."""
        if self.process.poll() is None:
            self.process.kill()
            self.process.communicate()


def process_state(pid: int) -> str:
    """The state letter of process ``pid`` in /proc (R, S, D, T, Z, ...), or "" once it is gone."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError, IndexError):
        return ""


def open_files(pid: int) -> list[str]:
    """The paths of the files process ``pid`` holds open."""
    names = []
    for fd in Path(f"/proc/{pid}/fd").iterdir() if Path(f"/proc/{pid}/fd").is_dir() else ():
        try:
            names.append(os.readlink(fd))
        except OSError:  # closed since
            pass
    return names


@contextmanager
def stopped(process: subprocess.Popen) -> Iterator[bool]:
    """Hold ``process`` still (SIGSTOP) for the block; yield whether it was still running (not ended) when it
    stopped; let it go on (SIGCONT) after. A signal sent inside the block reaches the process at the very point
    where the block saw it, the moment it goes on."""
    process.send_signal(signal.SIGSTOP)
    while process_state(process.pid) not in ("T", "t", "Z", "X", ""):
        time.sleep(0.0002)
    try:
        yield process_state(process.pid) in ("T", "t")
    finally:
        if process.poll() is None:
            process.send_signal(signal.SIGCONT)


def tilted_drawing_spec(drawing, key: str = "dxf", unit: str | None = None, thickness: float = 0.1,
                        unit_weight: float = 18000.0, friction: float = 30.0, title: str = "drawn") -> str:
    """The TOML of a wall drawn in ``drawing`` (``geometry.<key>``, in ``unit``: the drawing's own when None)
    standing on its lowest block, on a tilting table."""
    drawing_unit = f'drawing_unit = "{unit}"\n' if unit else ""
    return (f'title = "{title}"\n[geometry]\n{key} = "{drawing}"\n{drawing_unit}[wall]\nthickness = {thickness!r}\n'
            f'[material]\nunit_weight = {unit_weight!r}\nfriction_angle = {friction!r}\n'
            '[supports.base]\nkind = "fixed"\nselect = "lowest"\n[loading]\ntype = "tilt"\ndirection = 1\n')
