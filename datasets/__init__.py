"""The bundled walls: the paper's ten as specs (``datasets/<name>.toml``) and drawn examples
(``datasets/drawings/<name>.toml`` with their drawings), package ``masonryfw.datasets``.

This package is both the data and its accessors: a module ``masonryfw/datasets.py``
next to a data package of the same name would shadow it (or be shadowed by it,
depending on how the distribution is installed).
"""
from __future__ import annotations

from importlib import resources

from masonryfw.builders.kinds import load_spec
from masonryfw.runtime.errors import ModelError

#: Bundled case names, in the paper's order.
CASE_NAMES = (
    "test-8c", "test-12c",
    "panel-1", "panel-2", "panel-3", "panel-4", "panel-5",
    "facade-1", "facade-2", "facade-3",
)


#: Drawn example walls (``datasets/drawings``, see its ``generate.py``): a spec with ``[geometry]`` each.
DRAWN_NAMES = ("lact3-wall", "lact3-portal", "lact3-arch", "arch-settlement", "stepped-units", "gable-house")
#: Walls over a settlement profile (``[settlement]``, docs/settlements.md and docs/tunnels.md).
PROFILE_NAMES = ("facade-1-trough", "tunnel-facade")
#: Buildings in 3D laid from a ``[building]`` spec (docs/buildings.md).
BUILDING_NAMES = ("house-tunnel", "brick-house", "brick-terrace")
#: Buildings in 3D drawn block by block as an OBJ mesh (``datasets/drawings``, docs/import.md section 7).
DRAWN_3D_NAMES = ("drawn-corner",)
#: Every name :func:`bundled_spec_path` knows.
BUNDLED_NAMES = CASE_NAMES + DRAWN_NAMES + PROFILE_NAMES + BUILDING_NAMES + DRAWN_3D_NAMES


def bundled_spec_path(name: str):
    """The spec file of a bundled case or drawn example (an ``importlib.resources`` Traversable)."""
    if name in CASE_NAMES or name in PROFILE_NAMES or name in BUILDING_NAMES:
        return resources.files(__name__).joinpath(f"{name}.toml")
    if name in DRAWN_NAMES or name in DRAWN_3D_NAMES:
        return resources.files(__name__).joinpath("drawings", f"{name}.toml")
    raise ModelError(f"unknown bundled case {name!r}; valid names: {', '.join(BUNDLED_NAMES)}")


def bundled_cases() -> dict[str, str]:
    """``{name: title}`` of every bundled case, e.g. ``{"test-12c": "Test 12C", ...}``."""
    return {name: load_spec(bundled_spec_path(name))["title"] for name in CASE_NAMES}
