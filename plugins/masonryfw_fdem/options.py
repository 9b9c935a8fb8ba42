"""The options of the ``fdem`` solver (cheap to import: registration needs only these)."""
from __future__ import annotations

import masonryfw.plugin_api as mfp

OPTIONS = (
    mfp.Option("mode", str, "rigid",
              "rigid: every block a rigid body with 3 DOF (the paper's units have a very high E, "
              "so only the joints deform); deformable: every block a fan of constant-strain triangles "
              "(plane stress, block_young_modulus / block_poisson_ratio), the same joints",
              ("rigid", "deformable")),
    mfp.Option("settlement", float, None,
              "target settlement of the moving support [m] along settlement_direction (0: gravity only); "
              "auto: the model's settlement_target (a tunnel's S_max) if it has one, else settlement_ratio x "
              "masonry height", at_least=0.0),
    mfp.Option("settlement_ratio", float, 0.02,
              "target settlement as a share of the masonry height when settlement is auto (0: gravity only)",
              at_least=0.0),
    mfp.Option("loading_rate", float, 2e-3,
              "settlement velocity over sqrt(g x masonry height) (quasi-static when << 1)", above=0.0),
    mfp.Option("ramp_fraction", float, 0.05,
              "the velocity ramps up smoothly (half cosine) over this share of the target settlement time",
              at_least=0.0, at_most=1.0),
    mfp.Option("damping", float, 0.7,
              "local non-viscous damping coefficient (Cundall): each unbalanced force component is "
              "reduced by damping x |F| against the velocity; 0 = undamped dynamics", at_least=0.0, below=1.0),
    mfp.Option("contact_damping", float, 0.2,
              "normal dashpot at every contact as a share of critical damping (damps contact chatter, "
              "not sliding)", at_least=0.0),
    mfp.Option("dt_safety", float, 0.3, "time step = dt_safety x estimated critical time step", above=0.0),
    mfp.Option("penetration_ratio", float, None,
              "automatic contact stiffness: the mean base pressure of the wall's weight penetrates "
              "this share of the median unit height; auto: 1e-4 in 2D, 1.25e-5 in 3D (softer contacts set off an "
              "out-of-plane lean of a building's slender walls: docs/fdem.md)", above=0.0),
    mfp.Option("contact_stiffness", float, None,
              "normal contact stiffness per unit contact length [N m-2]; auto: from penetration_ratio", above=0.0),
    mfp.Option("min_contact_length", float, 0.01,
              "two faces overlapping less than this share of the median unit height are not in contact "
              "(blocks meeting corner to corner carry nothing)", above=0.0),
    mfp.Option("shear_stiffness_ratio", float, 0.5, "tangential / normal contact stiffness", above=0.0),
    mfp.Option("load_factor", float, None,
              "multiplier of live_load applied to the masonry blocks with the dead load; auto: 0, and a model "
              "without a moving support but with a live load (a tilting table) gets the load-factor search"),
    mfp.Option("search_first", float, 0.1, "load-factor search: the first trial multiplier (then doubled until "
              "one is unstable, then bisected)", above=0.0),
    mfp.Option("search_tolerance", float, 1e-3, "load-factor search: stop when the stable and the unstable "
              "multipliers are this close", above=0.0),
    mfp.Option("search_limit", float, 10.0, "load-factor search: the largest multiplier tried", above=0.0),
    mfp.Option("collapse_motion", float, 1.0,
              "load-factor search: a trial is unstable once a block has moved this share of the median unit "
              "height from where it rested (centroid plus rotation times radius)", above=0.0),
    mfp.Option("gravity_time", float, None,
              "duration of the gravity phase [s]; auto: until the unbalanced-force ratio is below rest_tolerance",
              above=0.0),
    mfp.Option("load_ramp", float, 0.0,
              "the loads grow smoothly (half cosine) over this time [s] at the start; 0 = applied at once",
              at_least=0.0),
    mfp.Option("rest_tolerance", float, 1e-5, "unbalanced force / applied load at which the wall is at rest",
              above=0.0),
    mfp.Option("max_steps", int, 20_000_000, "hard limit on the number of time steps", above=0),
    mfp.Option("records", int, 400, "history records over the target settlement", above=0),
    mfp.Option("plateau_tolerance", float, None,
              "stop when the reaction varies less than this share of the dead reaction over "
              "plateau_window of the target settlement; 0 = always run to the target; auto: 0 when the target "
              "is the model's settlement_target, else 0.005", at_least=0.0),
    mfp.Option("plateau_window", float, 0.25, "share of the target settlement over which the plateau is judged",
              above=0.0, at_most=1.0),
    mfp.Option("buffer_ratio", float, 0.1,
              "contact detection buffer as a share of the median unit height; the pair list is rebuilt "
              "when a block has moved half of it", above=0.0),
    mfp.Option("max_contact_angle", float, 40.0, "largest angle [deg] between two faces still in contact",
              above=0.0, below=90.0),
    mfp.Option("reclip_ratio", float, 1e-4,
              "3D: a face pair's overlap is clipped again once its blocks have moved against each other by this "
              "share of the smaller block's radius (its points stay on block A until then; 0 = whenever they "
              "have moved)",
              at_least=0.0),
    mfp.Option("rotational_inertia", str, "scaled",
              "3D: scaled: each block's inertia tensor is multiplied by the factor (at least 1, about 3 for a brick) "
              "that makes its rotation no stiffer than the stiffest block's translation, so the time step is "
              "translation's (sqrt(3) fewer steps; masses, loads and equilibria unchanged: for quasi-static runs); "
              "physical: the polyhedra's own", ("scaled", "physical")),
    mfp.Option("sleep", float, 0.0,
              "blocks slower than this share of the settlement velocity for sleep_steps steps sleep "
              "(not integrated) until a contact moving faster wakes them; 0 = no sleeping", at_least=0.0),
    mfp.Option("sleep_steps", int, 200, "consecutive slow steps before a block sleeps", above=0),
    mfp.Option("wake_force", float, 0.01,
              "a sleeping block wakes when its unbalanced force exceeds this share of its load", above=0.0),
    mfp.Option("threads", int, None,
              "threads of the contact and block loops (numba, at most NUMBA_NUM_THREADS); auto: one below 300 "
              "blocks, else the count that runs fastest on the machine as it is, measured as the run goes (a "
              "busy machine makes more threads slower); the trajectory does not depend on it, bit for bit",
              at_least=1),
    mfp.Option("snapshots", float, (), "settlements [m] at which block positions are stored (comma-separated); "
              "none given, a 3D run stores 20 evenly up to its settlement (the VTK export's time series)",
              many=True, at_least=0.0),
)
