"""Type stub of the public API: the imports ``__init__.py`` performs lazily, on first use
(lazy_loader.attach_stub reads them from here; Scientific Python SPEC 1)."""

from .api import SolvePlan, compare, estimate, plot_table, render, solve, solve_plan
from .builder import STAND_IN_GROUND, build, load_spec, load_wall
from .checks import Problem, check
from .damage import DAMAGE_LIMITS, Cracks, damage_category, distortion, support_profile, widest_crack
from .datasets import BUNDLED_NAMES, CASE_NAMES, DRAWN_NAMES, PROFILE_NAMES, bundled_cases, bundled_spec_path
from .describe import describe_model
from .dofs import block_loads, block_motion, load_variables, motion_variables
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
from .hookspecs import hookimpl
from .inputs import InputError, fits_in_memory, read_text, regular_file
from .interfaces import detect_interfaces
from .io import (
    check_output_path,
    content_sha256,
    open_dataset,
    save,
    save_figure,
    save_text,
    sha256_file,
    write_atomically,
)
from .lazy import lazy
from .linalg import cholesky_factor, has_cholmod
from .locks import BusyError, claim, release
from .model import checked_model, made_once
from .options import Option, parse_option_pairs, resolve_options, unknown_name_message
from .plausibility import PlausibilityWarning, plausibility
from .profiles import Profile, model_profile, settlement_profile
from .progress import ProgressCallback, interruptible, no_progress, progress_bar
from .provenance import core_version, options_json, solver_version
from .records import Comparator, Estimate, Plotter, Solver, Variant
from .registry import get_comparator, get_plotter, get_solver, installed_solvers, plugin_manager
from .resources import duration_text, size_text
from .roles import masonry_blocks, masonry_joints, support_blocks
from .schema import FORMAT_VERSION, flags, load_schema, variable_attrs
from .semantics import (
    CRACK_THRESHOLD,
    ModelScales,
    at_threshold,
    connected_components,
    crack_indicator,
    cracked_joints,
    dead_reaction,
    indicator_at,
    interface_states,
    joint_motion,
    macro_blocks,
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
)
from .signals import WriteInterrupted
from .sources import SPEC_SUFFIXES, input_files, is_spec, open_checked, open_model, source_path
from .spec import dump_toml
from .summary import (
    DIAGNOSIS_COLUMNS,
    KeyNumber,
    Row,
    candidate_text,
    csv_text,
    diagnosis_rows,
    headline_rows,
    headline_text,
    key_numbers,
    result_label,
    result_options,
    score_rows,
    stages_text,
    text_table,
)
from .version import __version__ as __version__

__all__ = [
    # Models: from a spec, a drawing, a file or a bundled case
    "STAND_IN_GROUND", "build", "load_spec", "load_wall",
    "SPEC_SUFFIXES", "input_files", "is_spec", "open_checked", "open_model", "source_path",
    "checked_model", "describe_model", "made_once",
    "BUNDLED_NAMES", "CASE_NAMES", "DRAWN_NAMES", "PROFILE_NAMES", "bundled_cases", "bundled_spec_path",
    "DxfLines", "read_dxf_lines",
    "dump_toml",
    "Profile", "model_profile", "settlement_profile",
    "ground_model", "over_profile",
    "detect_interfaces",
    "Problem", "check",
    "PlausibilityWarning", "plausibility",
    # Running plugins: solve, estimate, compare, draw
    "SolvePlan", "compare", "estimate", "plot_table", "render", "solve", "solve_plan",
    "get_comparator", "get_plotter", "get_solver", "installed_solvers", "plugin_manager",
    "__version__", "core_version", "options_json", "solver_version",
    # Writing a plugin: records, options, hooks
    "Comparator", "Estimate", "Plotter", "Solver", "Variant", "hookimpl", "lazy",
    "Option", "parse_option_pairs", "resolve_options", "unknown_name_message",
    "ProgressCallback", "interruptible", "no_progress", "progress_bar",
    # What results mean: one definition for every solver
    "CRACK_THRESHOLD", "KeyNumber", "ModelScales", "at_threshold", "connected_components", "crack_indicator",
    "cracked_joints", "dead_reaction", "indicator_at", "interface_states", "joint_motion", "key_numbers", "macro_blocks",
    "masonry_blocks", "masonry_joints", "model_scales", "nearest_interface", "plastic_crack_indicator",
    "point_motion", "polar_moment", "refuse_rigid_settlement", "relative_motion", "rigid_fit", "settlement_reaction",
    "settlement_weights", "support_blocks",
    "DAMAGE_LIMITS", "Cracks", "damage_category", "distortion", "support_profile", "widest_crack",
    "block_loads", "block_motion", "load_variables", "motion_variables",
    "DERIVED_GEOMETRY_VARIABLES", "block_bounds", "block_offsets", "convex_blocks", "convex_pieces",
    "derive_geometry", "interface_frame", "model_scale", "node_block", "point_segment_distance",
    "polygon_area_centroid", "triangulated",
    # Reading and writing files
    "check_output_path", "content_sha256", "open_dataset", "save", "save_figure", "save_text", "sha256_file",
    "write_atomically",
    "fits_in_memory", "read_text", "regular_file",
    "claim", "release",
    "FORMAT_VERSION", "flags", "load_schema", "variable_attrs",
    # Tables and text: what the CLI prints and a report shows
    "DIAGNOSIS_COLUMNS", "Row", "candidate_text", "csv_text", "diagnosis_rows", "headline_rows", "headline_text",
    "result_label", "result_options", "score_rows", "stages_text", "text_table",
    "duration_text", "size_text",
    "cholesky_factor", "has_cholmod",
    # Errors
    "Interrupted", "MasonryError", "ModelError", "PluginError", "SolveError", "SpecError", "listed",
    "InputError",
    "BusyError",
    "WriteInterrupted",
]
