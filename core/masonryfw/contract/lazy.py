"""Callables that import what they stand for on first use: a plugin names its solve, estimate and plot functions
as ``"package.module:function"``, so listing the plugins or running one solver never imports another plugin's
heavy dependencies (numba, matplotlib, dask, ...)."""
from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any

from ..runtime.errors import PluginError


def lazy(target: str) -> Callable[..., Any]:
    """A callable that imports ``"package.module:function"`` on its first call.

    Plugins build their records with ``lazy(...)`` callables, so listing the
    plugins or running one solver never imports another plugin's heavy
    dependencies (numba, matplotlib, dask, ...).
    """
    module_name, _, attribute = target.partition(":")
    if not module_name or not attribute:
        raise PluginError(f"lazy target {target!r} is not of the form 'package.module:function'")

    def resolve() -> Callable[..., Any]:
        return getattr(importlib.import_module(module_name), attribute)

    def call(*args: Any, **kwargs: Any) -> Any:
        return resolve()(*args, **kwargs)

    call.__name__ = call.__qualname__ = attribute
    call.__module__ = module_name
    call.__doc__ = f"Calls {target} (imported on first use)."
    call.resolve = resolve  # type: ignore[attr-defined]  # the target itself: imports it now
    return call


def resolved(function: Callable[..., Any]) -> Callable[..., Any]:
    """The function a :func:`lazy` callable stands for (imported now); any other callable as it is."""
    resolve = getattr(function, "resolve", None)
    return resolve() if callable(resolve) else function
