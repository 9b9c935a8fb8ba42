"""The paper's ten walls as bundled specs (``datasets/<name>.toml``, package ``masonryfw.datasets``).

This package is both the data and its accessors: a module ``masonryfw/datasets.py``
next to a data package of the same name would shadow it (or be shadowed by it,
depending on how the distribution is installed).
"""
from __future__ import annotations

from importlib import resources

from masonryfw.builder import load_spec
from masonryfw.errors import ModelError

#: Bundled case names, in the paper's order.
CASE_NAMES = (
    "test-8c", "test-12c",
    "panel-1", "panel-2", "panel-3", "panel-4", "panel-5",
    "facade-1", "facade-2", "facade-3",
)


def bundled_spec_path(name: str):
    """The spec file of a bundled case (an ``importlib.resources`` Traversable)."""
    if name not in CASE_NAMES:
        raise ModelError(f"unknown bundled case {name!r}; valid names: {', '.join(CASE_NAMES)}")
    return resources.files(__name__).joinpath(f"{name}.toml")


def bundled_cases() -> dict[str, str]:
    """``{name: title}`` of every bundled case, e.g. ``{"test-12c": "Test 12C", ...}``."""
    return {name: load_spec(bundled_spec_path(name))["title"] for name in CASE_NAMES}
