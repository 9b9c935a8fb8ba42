"""What the sweep studies of docs/scripts share: their command line, a sweep run into its store, its report."""
from __future__ import annotations

import argparse
from pathlib import Path

from masonryfw_sweep import failed_points, run_sweep


def arguments(description: str, store: Path) -> argparse.Namespace:
    """``--workers`` (dask's local cluster) and ``--store`` (the results a re-run reuses, default ``store``)."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--store", type=Path, default=store)
    args = parser.parse_args()
    args.store.mkdir(parents=True, exist_ok=True)
    return args


def run_plan(client, store: Path, name: str, plan):
    """The sweep ``plan`` run on ``client`` into ``store/<name>.store``; its failures and its solve time printed."""
    path = store / f"{name}.store"
    path.mkdir(parents=True, exist_ok=True)
    result = run_sweep(plan, client, path, store)
    for where, message in failed_points(result):
        print(f"{name} failed: {where}: {message}")
    print(f"{name}: {result.status.size} points, wall time of the solves {float(result.wall_time_s.sum()):.1f} s")
    return result


def values(items) -> str:
    """A sweep parameter's values as the CLI writes them: ``0.5,1,2``."""
    return ",".join(f"{v:g}" for v in items)
