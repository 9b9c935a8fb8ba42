"""Where a search's scenarios are solved: here one by one, on local processes (``--workers``) or on a dask cluster
(``--scheduler``, as ``sweep`` does).

A *runner* takes the work (a function of a list of scenarios) and the scenarios in chunks, and yields each chunk's
outcomes as it is done, in any order: the search ranks them all at the end. Local processes are forked, so the
wall, the survey and the solver's imports are theirs without pickling; they ignore Ctrl-C, which the search
handles (the pool is terminated, those done are kept). On a cluster the diagnosis is scattered once and every
chunk is a task; the cluster is left running.
"""
from __future__ import annotations

import contextlib
import functools
import signal
from collections.abc import Callable, Iterable, Iterator
from typing import Any

Runner = Callable[[Callable[[list], list], list[list]], Iterable[list]]
#: Scenarios a chunk holds on processes or a cluster (one each here: Ctrl-C and the bar act on every one).
CHUNK = 8


def serial(work: Callable[[list], list], chunks: list[list]) -> Iterator[list]:
    for chunk in chunks:
        yield work(chunk)


def chunks(tables: list[dict], runner: Runner) -> list[list[dict]]:
    size = 1 if runner is serial else CHUNK
    return [tables[k:k + size] for k in range(0, len(tables), size)]


#: The work of the forked processes, set before the pool forks them (not pickled).
_FORKED: Callable[[list], list] | None = None


def work(function: Callable, diagnosis: Any, options: dict | None) -> Callable[[list], list]:
    """``function(diagnosis, options, chunk)`` of one chunk."""
    return functools.partial(function, diagnosis, options)


def _run_forked(chunk: list) -> list:
    assert _FORKED is not None
    return _FORKED(chunk)


def _worker_signals() -> None:
    """A forked worker ignores Ctrl-C (the search handles it) and dies quietly when the pool is terminated (the
    command's SIGTERM handler, inherited, would raise in it)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


@contextlib.contextmanager
def local_processes(workers: int) -> Iterator[Runner]:
    """A runner on ``workers`` forked processes; the pool terminated on leaving (at once after Ctrl-C)."""
    import multiprocessing

    def run(work: Callable[[list], list], chunks: list[list]) -> Iterator[list]:
        global _FORKED
        _FORKED = work
        pool = multiprocessing.get_context("fork").Pool(workers, initializer=_worker_signals)
        try:
            yield from pool.imap_unordered(_run_forked, chunks)
            pool.close()
        finally:
            pool.terminate()
            pool.join()
            _FORKED = None

    yield run


@contextlib.contextmanager
def dask_cluster(address: str) -> Iterator[Runner]:
    """A runner on the dask cluster at ``address`` (left running); a missing dask is named with its install."""
    try:
        from distributed import Client, as_completed
    except ImportError as exc:
        import masonryfw as mf

        raise mf.MasonryError("--scheduler needs dask's distributed: pip install 'dask[distributed]' (or "
                              "masonryfw[sweep])") from exc

    with Client(address) as client:
        def run(work: functools.partial, chunks: list[list]) -> Iterator[list]:
            [diagnosis] = client.scatter([work.args[0]], broadcast=True, hash=False)
            futures = [client.submit(work.func, diagnosis, *work.args[1:], chunk, pure=False) for chunk in chunks]
            try:
                for future in as_completed(futures):
                    yield future.result()
            finally:
                client.cancel(futures)

        yield run
