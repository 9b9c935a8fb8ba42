"""masonryfw: failure analysis of dry-joint masonry walls under foundation settlements.

The public API. Data flows one way::

    spec --build--> model --solve(plugin)--> result --compare/plot--> ...

Solver plugins import only the names exported here.
"""
from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version as _dist_version

try:
    __version__ = _dist_version("masonryfw")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"

from .errors import MasonryError, ModelError, PluginError, SolveError, SpecError
from .progress import ProgressCallback, no_progress
from .hookspecs import (
    Comparator,
    Option,
    Plotter,
    Solver,
    hookimpl,
    lazy,
    parse_option_pairs,
    resolve_options,
)
from .schema import FORMAT_VERSION, flags, load_schema, variable_attrs
from .geometry import (
    DERIVED_GEOMETRY_VARIABLES,
    block_bounds,
    block_offsets,
    derive_geometry,
    interface_frame,
    model_scale,
    node_block,
    polygon_area_centroid,
)
from .interfaces import detect_interfaces
from .checks import Problem, check
from .linalg import cholesky_factor, has_cholmod
from .io import add_history, content_sha256, open_dataset, open_model, save, save_figure, sha256_file
from .builder import build, dump_toml, load_spec
from .datasets import bundled_cases, bundled_spec_path
from .plugins import compare, get_comparator, get_plotter, get_solver, plugin_manager, render, solve

__all__ = [name for name in dir() if not name.startswith("_")]
