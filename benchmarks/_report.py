"""Write one benchmark's section of ``docs/benchmarks.md``, stamped with the machine and date.

Each benchmark script owns the section between ``<!-- begin:NAME -->`` and
``<!-- end:NAME -->`` and rewrites only that part, so scripts can run in any order.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import os
import platform
import re
from pathlib import Path

REPORT = Path(__file__).resolve().parent.parent / "docs" / "benchmarks.md"
HEADER = (
    "# Benchmarks\n\n"
    "Written by the scripts in `benchmarks/` (run `python benchmarks/<script>.py`); each section\n"
    "names the machine and date it was measured on. Times are wall-clock medians unless stated.\n"
)


def command_line(doc: str | None) -> argparse.ArgumentParser:
    """The benchmark's command line, its module docstring as the help (``--help`` runs nothing)."""
    return argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)


def machine() -> str:
    """One line describing this machine."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        mem_gib = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    except (ValueError, OSError):
        mem_gib = float("nan")
    return f"{cpu}, {os.cpu_count()} cores, {mem_gib:.0f} GiB, Python {platform.python_version()}, {platform.system()}"


def write_section(name: str, title: str, body: str) -> None:
    """Replace (or append) the section ``name`` of docs/benchmarks.md."""
    stamp = f"_Measured {_dt.date.today().isoformat()} on {machine()}._"
    section = f"<!-- begin:{name} -->\n## {title}\n\n{stamp}\n\n{body.strip()}\n<!-- end:{name} -->"
    text = REPORT.read_text() if REPORT.exists() else HEADER
    pattern = re.compile(rf"<!-- begin:{re.escape(name)} -->.*?<!-- end:{re.escape(name)} -->", re.S)
    text = pattern.sub(lambda _: section, text) if pattern.search(text) else text.rstrip() + "\n\n" + section + "\n"
    REPORT.parent.mkdir(parents=True, exist_ok=True)
    REPORT.write_text(text)
