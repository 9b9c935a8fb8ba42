"""Numba's compilations of the kernels, watched: on the first run after an install it compiles them (19.3 s of
Panel 5's 24.9 s on a cold cache, 2-core machine, 2026-11-27), on later runs it loads them from its cache.

:class:`Compilations` listens to numba's compile events (fired on a compilation, not on a load from the cache)
for the length of a solve: it says when the first starts and about how long it takes (a progress message),
measures their time (``compile_time_s``) and holds Ctrl-C and SIGTERM while they run
(:func:`masonryfw.plugin_api.signals_held`), taking them at the next event: raised anywhere inside, a
``KeyboardInterrupt`` lands in LLVM's callbacks into llvmlite, where it is dropped and loses the compiled code
("no compiled object yet"), or the run goes on as if nothing had happened. Panel 5's compilation fired 104
events, at most 4.6 s apart: a Ctrl-C is answered within that.
"""
from __future__ import annotations

import time
from contextlib import AbstractContextManager
from typing import Any

from numba.core import event

import masonryfw.plugin_api as mfp

#: Seconds to compile the kernels of a mode once (the rigid kernels: 19.3 s on the 2-core machine; the CST mode
#: compiles its own kernels beside the rigid detection).
COMPILE_SECONDS = {"rigid": 20.0, "deformable": 30.0}


class Compilations(event.Listener):
    """Listener of ``numba:compile`` (nested: a kernel's callees compile within it) for one solve."""

    def __init__(self, mode: str, progress):
        self.mode, self.progress = mode, progress
        self.seconds = 0.0
        self.depth = 0
        self.announced = False
        self.hold: AbstractContextManager[Any] | None = None
        self.checkpoint = lambda: None
        self.started = 0.0

    def on_start(self, event) -> None:
        if self.depth == 0:
            self.hold = mfp.signals_held()
            self.checkpoint = self.hold.__enter__()
            self.started = time.perf_counter()
        self.depth += 1  # before anything can raise: numba sends the end event of a start that raised
        if not self.announced:
            self.announced = True
            self.progress(0.0, f"fdem: compiling the solver once (about {COMPILE_SECONDS[self.mode]:.0f} s; "
                               "later runs load it from numba's cache)")
        self.checkpoint()

    def on_end(self, event) -> None:
        self.depth -= 1
        if self.depth > 0:
            self.checkpoint()
            return
        self.seconds += time.perf_counter() - self.started
        hold, self.hold, self.checkpoint = self.hold, None, lambda: None
        hold.__exit__(None, None, None)  # takes a signal held
