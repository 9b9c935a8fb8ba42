"""Type stub of the public API: the imports ``__init__.py`` performs lazily, on first use
(lazy_loader.attach_stub reads them from here; Scientific Python SPEC 1)."""

from .api import SolvePlan, compare, estimate, plot_table, render, solve, solve_plan
from .builders.ground import ground_model, over_profile
from .builders.kinds import STAND_IN_GROUND, build, load_spec, load_wall
from .builders.plausibility import PlausibilityWarning, plausibility
from .builders.sources import open_checked, open_model
from .contract.registry import get_comparator, get_plotter, get_solver, installed_solvers
from .datasets import (
    BUILDING_NAMES,
    BUNDLED_NAMES,
    CASE_NAMES,
    DRAWN_3D_NAMES,
    DRAWN_NAMES,
    PROFILE_NAMES,
    bundled_cases,
    bundled_spec_path,
)
from .format.checks import Problem, check
from .format.io import open_dataset, save, save_figure
from .format.model import checked_model
from .geometry.interfaces import detect_interfaces
from .ground.profiles import Profile, model_profile, settlement_profile
from .readers.spec import dump_toml
from .results.damage import DAMAGE_LIMITS, Cracks, damage_category, widest_crack
from .results.describe import describe_model
from .results.semantics import CRACK_THRESHOLD, at_threshold, cracked_joints, dead_reaction, settlement_reaction
from .results.summary import (
    KeyNumber,
    capacity_text,
    damage_text,
    headline_text,
    key_numbers,
    load_word,
    result_label,
    stages_text,
    walls_text,
)
from .runtime.errors import Interrupted, MasonryError, ModelError, PluginError, SolveError, SpecError
from .runtime.inputs import InputError
from .runtime.locks import BusyError
from .runtime.signals import WriteInterrupted
from .runtime.version import __version__ as __version__

__all__ = [
    # Models: from a spec, a drawing, a file or a bundled case
    "STAND_IN_GROUND", "build", "load_spec", "load_wall", "dump_toml",
    "open_model", "open_checked", "checked_model", "describe_model",
    "BUILDING_NAMES", "BUNDLED_NAMES", "CASE_NAMES", "DRAWN_3D_NAMES", "DRAWN_NAMES", "PROFILE_NAMES", "bundled_cases", "bundled_spec_path",
    "Profile", "model_profile", "settlement_profile", "ground_model", "over_profile",
    "detect_interfaces", "Problem", "check", "PlausibilityWarning", "plausibility",
    # Solving, comparing, drawing
    "SolvePlan", "compare", "estimate", "plot_table", "render", "solve", "solve_plan",
    "get_comparator", "get_plotter", "get_solver", "installed_solvers", "__version__",
    # What results mean
    "CRACK_THRESHOLD", "at_threshold", "cracked_joints", "dead_reaction", "settlement_reaction",
    "KeyNumber", "key_numbers", "headline_text", "load_word", "damage_text", "result_label", "stages_text",
    "capacity_text", "walls_text",
    "DAMAGE_LIMITS", "Cracks", "damage_category", "widest_crack",
    # Files
    "open_dataset", "save", "save_figure",
    # Errors
    "MasonryError", "SpecError", "ModelError", "PluginError", "SolveError", "InputError", "BusyError",
    "Interrupted", "WriteInterrupted",
]
