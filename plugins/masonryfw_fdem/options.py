"""The options of the ``fdem`` solver (cheap to import: registration needs only these)."""
from __future__ import annotations

import masonryfw as mf

OPTIONS = (
    mf.Option("mode", str, "rigid",
              "rigid: every block a rigid body with 3 DOF (the paper's units have a very high E, "
              "so only the joints deform); deformable: every block a fan of constant-strain triangles "
              "(plane stress, block_young_modulus / block_poisson_ratio), the same joints",
              ("rigid", "deformable")),
    mf.Option("settlement", float, 0.0,
              "target settlement of the moving support [m] along settlement_direction; "
              "0 = settlement_ratio x masonry height"),
    mf.Option("settlement_ratio", float, 0.02, "target settlement as a share of the masonry height (when settlement = 0)"),
    mf.Option("loading_rate", float, 2e-3,
              "settlement velocity over sqrt(g x masonry height) (quasi-static when << 1)"),
    mf.Option("ramp_fraction", float, 0.05,
              "the velocity ramps up smoothly (half cosine) over this share of the target settlement time"),
    mf.Option("damping", float, 0.7,
              "local non-viscous damping coefficient (Cundall): each unbalanced force component is "
              "reduced by damping x |F| against the velocity; 0 = undamped dynamics"),
    mf.Option("contact_damping", float, 0.2,
              "normal dashpot at every contact as a share of critical damping (damps contact chatter, "
              "not sliding)"),
    mf.Option("dt_safety", float, 0.3, "time step = dt_safety x estimated critical time step"),
    mf.Option("penetration_ratio", float, 1e-4,
              "automatic contact stiffness: the mean base pressure of the wall's weight penetrates "
              "this share of the median unit height"),
    mf.Option("contact_stiffness", float, 0.0,
              "normal contact stiffness per unit contact length [N m-2]; 0 = from penetration_ratio"),
    mf.Option("min_contact_length", float, 0.01,
              "two faces overlapping less than this share of the median unit height are not in contact "
              "(blocks meeting corner to corner carry nothing)"),
    mf.Option("shear_stiffness_ratio", float, 0.5, "tangential / normal contact stiffness"),
    mf.Option("load_factor", float, 0.0, "multiplier of live_load applied to the masonry blocks with the dead load"),
    mf.Option("gravity_time", float, 0.0,
              "duration of the gravity phase [s]; 0 = until the unbalanced-force ratio is below rest_tolerance"),
    mf.Option("load_ramp", float, 0.0,
              "the loads grow smoothly (half cosine) over this time [s] at the start; 0 = applied at once"),
    mf.Option("rest_tolerance", float, 1e-5, "unbalanced force / applied load at which the wall is at rest"),
    mf.Option("max_steps", int, 20_000_000, "hard limit on the number of time steps"),
    mf.Option("records", int, 400, "history records over the target settlement"),
    mf.Option("plateau_tolerance", float, 0.005,
              "stop when the reaction varies less than this share of the dead reaction over "
              "plateau_window of the target settlement; 0 = always run to the target"),
    mf.Option("plateau_window", float, 0.25, "share of the target settlement over which the plateau is judged"),
    mf.Option("buffer_ratio", float, 0.1,
              "contact detection buffer as a share of the median unit height; the pair list is rebuilt "
              "when a block has moved half of it"),
    mf.Option("max_contact_angle", float, 40.0, "largest angle [deg] between two faces still in contact"),
    mf.Option("sleep", float, 0.0,
              "blocks slower than this share of the settlement velocity for sleep_steps steps sleep "
              "(not integrated) until a contact moving faster wakes them; 0 = no sleeping"),
    mf.Option("sleep_steps", int, 200, "consecutive slow steps before a block sleeps"),
    mf.Option("crack_threshold", float, 0.02,
              "a joint moving less than this share of the largest joint motion is intact"),
    mf.Option("snapshots", str, "", "comma-separated settlements [m] at which block positions are stored"),
)
