"""masonryfw: failure analysis of dry-joint masonry walls under foundation settlements.

The public API. Data flows one way::

    spec --build--> model --solve(plugin)--> result --compare/plot--> ...

Solver plugins import only the names exported here.
"""
from __future__ import annotations

from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as _dist_version

try:
    __version__ = _dist_version("masonryfw")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"

from .builder import STAND_IN_GROUND, build, load_spec, load_wall
from .checks import Problem, check
from .damage import DAMAGE_LIMITS, Cracks, damage_category, distortion, support_profile, widest_crack
from .datasets import BUNDLED_NAMES, CASE_NAMES, DRAWN_NAMES, PROFILE_NAMES, bundled_cases, bundled_spec_path
from .dofs import block_loads, block_motion, load_variables, motion_variables, upgrade
from .drawing import DxfLines, read_dxf_lines
from .errors import Interrupted, MasonryError, ModelError, PluginError, SolveError, SpecError, listed
from .geometry import (
    DERIVED_GEOMETRY_VARIABLES,
    block_bounds,
    block_offsets,
    convex_blocks,
    convex_pieces,
    derive_geometry,
    interface_frame,
    model_scale,
    node_block,
    point_segment_distance,
    polygon_area_centroid,
    triangulated,
)
from .ground import ground_model, over_profile
from .hookspecs import (
    AUTO,
    Comparator,
    Estimate,
    Option,
    Plotter,
    Solver,
    Variant,
    hookimpl,
    lazy,
    parse_option_pairs,
    resolve_options,
    unknown_name_message,
)
from .inputs import InputError, read_text, regular_file
from .interfaces import detect_interfaces
from .io import (
    add_history,
    check_output_path,
    content_sha256,
    open_dataset,
    save,
    save_figure,
    save_text,
    sha256_file,
    write_atomically,
)
from .linalg import cholesky_factor, has_cholmod
from .locks import BusyError, claim, release
from .model import checked_model, model_part, open_model
from .plausibility import PlausibilityWarning, plausibility
from .plugins import (
    compare,
    core_version,
    estimate,
    get_comparator,
    get_plotter,
    get_solver,
    installed_solvers,
    options_json,
    plot_table,
    plugin_manager,
    render,
    solve,
    solver_version,
)
from .profiles import Profile, model_profile, settlement_profile
from .progress import ProgressCallback, StderrBar, interruptible, no_progress, progress_bar
from .resources import available_memory, duration_text, size_text
from .schema import FORMAT_VERSION, flags, load_schema, variable_attrs
from .semantics import (
    INTACT_SHARE,
    KeyNumber,
    ModelScales,
    connected_components,
    crack_indicator,
    dead_reaction,
    interface_states,
    joint_motion,
    key_numbers,
    macro_blocks,
    masonry_blocks,
    masonry_joints,
    model_scales,
    nearest_interface,
    plastic_crack_indicator,
    point_motion,
    polar_moment,
    refuse_rigid_settlement,
    relative_motion,
    rigid_fit,
    settlement_reaction,
    settlement_weights,
    states_at,
    support_blocks,
)
from .signals import WriteInterrupted
from .spec import dump_toml
from .summary import (
    DIAGNOSIS_COLUMNS,
    Row,
    candidate_text,
    csv_text,
    diagnosis_rows,
    headline_rows,
    headline_text,
    result_label,
    result_options,
    score_rows,
    stages_text,
    text_table,
)

__all__ = [name for name in dir() if not name.startswith("_")]
