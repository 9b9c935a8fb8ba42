"""Every documentation script and benchmark imports and answers ``--help`` (without running its work), as
scikit-fem imports its examples in its tests: a script that has drifted from the public API fails here,
not when someone next regenerates the docs."""
from __future__ import annotations

import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SCRIPTS = sorted(p for folder in ("docs/scripts", "benchmarks") for p in (ROOT / folder).glob("*.py")
                 if not p.name.startswith("_"))


def help_of(script: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(script), "--help"], capture_output=True, text=True, timeout=120,
                          cwd=script.parent)


def test_every_script_and_benchmark_imports_and_answers_help():
    assert len(SCRIPTS) >= 20
    with ThreadPoolExecutor(max_workers=4) as pool:
        answers = dict(zip(SCRIPTS, pool.map(help_of, SCRIPTS)))
    failed = {str(p.relative_to(ROOT)): (a.returncode, a.stderr[-400:]) for p, a in answers.items()
              if a.returncode != 0 or "usage:" not in a.stdout}
    assert not failed, failed
