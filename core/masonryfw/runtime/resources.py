"""Memory this process may use, and the refusal of a run that would not fit in it.

A solve that runs out of memory is killed by the kernel with nothing written and no
message; refusing it before it starts, naming the option that makes it smaller, is
kinder. The limit is the smaller of the system's available memory and what the
cgroup (a container, a CI runner) leaves; ``MASONRYFW_MEMORY_LIMIT`` overrides both
(bytes, or with a unit: ``512MiB``, ``4GiB``, ``2GB``).
"""
from __future__ import annotations

import os
import re
from pathlib import Path

from .errors import SolveError

MEMORY_LIMIT_VARIABLE = "MASONRYFW_MEMORY_LIMIT"
_UNITS = {"": 1, "b": 1, "kb": 1e3, "mb": 1e6, "gb": 1e9, "kib": 2**10, "mib": 2**20, "gib": 2**30}


def parse_bytes(text: str) -> float:
    """``"4GiB"`` -> 4294967296.0; a plain number is bytes."""
    match = re.fullmatch(r"\s*([0-9]+(?:\.[0-9]*)?(?:e[+-]?[0-9]+)?)\s*([a-z]*)\s*", text.lower())
    if not match or match.group(2) not in _UNITS:
        raise SolveError(f"{MEMORY_LIMIT_VARIABLE}={text!r} is not a size (bytes, or a number with "
                         "kB, MB, GB, KiB, MiB or GiB)")
    return float(match.group(1)) * _UNITS[match.group(2)]


def _meminfo_available() -> float | None:
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                return float(line.split()[1]) * 1024
    except OSError:
        pass
    return None


def _cgroup_headroom() -> float | None:
    """What the cgroup v2 memory limit leaves (None without a limit)."""
    root = Path("/sys/fs/cgroup")
    try:
        limit = (root / "memory.max").read_text().strip()
        if limit == "max":
            return None
        return float(limit) - float((root / "memory.current").read_text())
    except (OSError, ValueError):
        return None


def available_memory() -> float:
    """Bytes a new run may use (``inf`` when nothing says)."""
    override = os.environ.get(MEMORY_LIMIT_VARIABLE)
    if override:
        return parse_bytes(override)
    known = [v for v in (_meminfo_available(), _cgroup_headroom()) if v is not None]
    return min(known) if known else float("inf")


def size_text(nbytes: float) -> str:
    """``300 MiB``, ``1.5 GiB``, ``7.0 PiB`` (``more than any machine has`` past what a float counts)."""
    if not nbytes < float("inf"):
        return "more than any machine has"
    for power, unit in ((50, "PiB"), (40, "TiB"), (30, "GiB")):
        if nbytes >= 2**power:
            return f"{nbytes / 2**power:.1f} {unit}" if nbytes < 2**60 else f"{nbytes / 2**power:.3g} {unit}"
    return f"{nbytes / 2**20:.0f} MiB"


def count_text(count: float) -> str:
    """``about 12,345`` (``about 1.2e+13`` past ten digits, ``more than 1e+308`` past what a float counts): a count
    estimated before the work."""
    if not count < float("inf"):
        return "more than 1e+308"
    return f"about {count:,.0f}" if count < 1e10 else f"about {count:.3g}"


def duration_text(seconds: float) -> str:
    """``40 s``, ``12 min``, ``3.1 h``."""
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h" if seconds < 3.6e7 else f"{seconds / 3600:.3g} h"


def require_memory(solver: str, memory: float, basis: str, advice: str = "") -> None:
    """Raise :class:`SolveError` when a run's estimated ``memory`` [bytes] (worked out so: ``basis``) exceeds
    :func:`available_memory`, with the ``advice`` that makes it smaller."""
    available = available_memory()
    if memory <= available:
        return
    hint = f"; to make it smaller: {advice}" if advice else ""
    raise SolveError(
        f"solver {solver}: this run needs about {size_text(memory)} of memory ({basis}) "
        f"and {size_text(available)} is available ({MEMORY_LIMIT_VARIABLE} sets the limit){hint}"
    )
