"""What a plugin shares with the core: ``import masonryfw.plugin_api as mfp``.

The user's API is ``masonryfw`` (``mf``): build, solve, compare, draw, read what results mean. A plugin, the
command line and the conformance kit need more: the records and hooks of the contract, the options, the
progress, the geometry of the ragged polygon layout, the role masks, the fields every solver's result derives
the same way, the files written atomically and read safely, the text tables, the sparse Cholesky. They live
here, documented in docs/api.md ("For plugin authors"), and like ``mf`` every name is imported on first use
(lazy_loader, Scientific Python's SPEC 1): importing this module costs nothing.
"""
import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach("masonryfw", submod_attrs={
    "api": ["size_asked"],
    "assessment": ["LTSM_LIMITS", "POISSON", "Part", "assess", "deep_beam_strains", "ltsm_category", "volume_loss_per_settlement", "wall_extent"],
    "command_kit": ["ADDRESS", "LENGTH", "Number", "OPTIONS", "PROGRESS", "command_line"],
    "cores": ["core_share", "cores", "free_cores", "machine_load"],
    "damage": ["distortion", "refuse_not_standing", "standing_text", "support_profile"],
    "dofs": ["block_loads", "block_motion", "load_variables", "motion_variables"],
    "drawing": ["DxfLines", "Elevation", "read_drawing", "read_dxf_lines", "read_elevation"],
    "errors": ["listed"],
    "derived": ["DERIVED_VARIABLES", "derive_geometry"],
    "geometry": ["DERIVED_GEOMETRY_VARIABLES", "block_bounds", "block_offsets", "convex_blocks", "convex_pieces", "interface_frame", "model_scale", "node_block", "point_segment_distance", "polygon_area_centroid", "triangulated"],
    "ground_plan": ["GroundInPlan", "ground_in_plan"],
    "hookspecs": ["hookimpl"],
    "inputs": ["fits_in_memory", "read_text", "regular_file"],
    "io": ["FIGURE_FORMATS", "check_output_path", "content_sha256", "save_text", "sha256_file", "write_atomically"],
    "lazy": ["lazy"],
    "linalg": ["cholesky_factor", "has_cholmod"],
    "locks": ["claim", "release"],
    "model": ["made_once"],
    "model3d": ["contacts_of", "interface_points", "polyhedra_of", "require_space", "space", "twin"],
    "options": ["Option", "parse_option_pairs", "resolve_options", "unknown_name_message"],
    "polyhedra": ["Contacts", "Polyhedra", "boxes", "face_normals_areas", "find_contacts", "plane_frame", "polygon_normals", "prisms", "second_moments", "volumes_centroids"],
    "progress": ["ProgressCallback", "interruptible", "no_progress", "progress_bar"],
    "provenance": ["core_version", "options_json", "solver_version"],
    "records": ["Comparator", "Estimate", "Plotter", "Solver", "Variant"],
    "registry": ["plugin_manager"],
    "resources": ["count_text", "duration_text", "size_text"],
    "roles": ["ROLE", "jointed_blocks", "masonry_blocks", "masonry_joints", "support_blocks"],
    "schema": ["FORMAT_VERSION", "flags", "load_schema", "variable_attrs"],
    "graph": ["connected_components"],
    "semantics": ["ModelScales", "crack_indicator", "indicator_at", "interface_states", "joint_motion", "macro_blocks", "model_scales", "nearest_interface", "plastic_crack_indicator", "point_motion", "polar_moment", "refuse_rigid_settlement", "relative_motion", "rigid_fit", "settlement_weights"],
    "sources": ["SPEC_SUFFIXES", "input_files", "is_spec", "source_path"],
    "summary": ["DIAGNOSIS_COLUMNS", "QUASI_STATIC_RATIO", "Row", "quasi_static_text", "candidate_text", "csv_text", "R0_SPREAD", "diagnosis_rows", "force_text", "headline_rows", "r0_text", "result_options", "score_rows", "text_table"],
})
