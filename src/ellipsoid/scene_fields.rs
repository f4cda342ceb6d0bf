//! The field reference of the `kind = "ellipsoids"` scene file (Roig03's interacting ellipsoids): one row per key of
//! `ellipsoid::scene::SceneFile` (which reads its bounds from here), printed by `rubblepile check --explain
//! ellipsoids`. The rows the validator checks a plain range with are named constants, and the validator reads its
//! bounds from them ([`crate::io::scene_file::Validator::within`]); the rest state the rule the validator's own code
//! applies. The meanings restate the rustdoc of the schema structs in one line each.

use crate::ellipsoid::gravity_tree::{DEFAULT_THETA, MAX_THETA, TREE_FROM};
use crate::io::scene_fields::{FieldDoc, Range, SceneReference, TableDoc};
use crate::io::scene_file::MIN_RTOL;

/// Largest κ accepted (`model.kappa`, or the one `model.calibrate` gives): every pair's contact amplitude holds
/// `e^{κλ}` with `λ ≤ 2` (Roig03 Eq. 12), and at κ = 175 that factor is 1e152, half the range of an `f64`; the other
/// half is left for `G m_i m_j (R_i + R_j)²`. The committed scenes and benches use κ ≤ 50, Roig03 κ ≈ 10–30.
pub const MAX_KAPPA: f64 = 175.0;

/// Two bodies whose centres lie closer than this fraction of the smaller of their smallest semi-axes are refused
/// at t = 0 as coincident or deeply overlapping (their contact energy is near its full-overlap maximum and their
/// monopole gravity near its singularity). Relaxed piles touch and overlap slightly: the committed targets keep
/// their centres at least 1.87 smallest semi-axes apart (N10000_T4), so 0.5 refuses none of them.
pub const MIN_CENTRE_SEPARATION: f64 = 0.5;

/// `scene.t_end`.
pub const T_END: FieldDoc = FieldDoc {
    key: "scene.t_end",
    unit: "s",
    default: "required",
    range: Range::Positive,
    meaning: "end time of the run; it starts at t = 0",
};

/// `model.kappa`.
pub const KAPPA: FieldDoc = FieldDoc {
    key: "model.kappa",
    unit: "-",
    default: "(kappa or calibrate)",
    range: Range::open_closed(1.5, MAX_KAPPA),
    meaning: "width of the Gaussian mass distribution (Roig03 Eq. 2); larger = stiffer; exactly one of kappa, calibrate",
};

/// `model.calibrate.beta`.
pub const CALIBRATE_BETA: FieldDoc = FieldDoc {
    key: "model.calibrate.beta",
    unit: "-",
    default: "required",
    range: Range::Positive,
    meaning: "contact barrier over the kinetic energy at speed v (Roig03 Eq. 14)",
};

/// `model.calibrate.v`.
pub const CALIBRATE_V: FieldDoc = FieldDoc {
    key: "model.calibrate.v",
    unit: "m/s",
    default: "required",
    range: Range::Positive,
    meaning: "relative speed the contact must withstand (Roig03 Eq. 14)",
};

/// `physics.gravity.G`.
pub const GRAVITY_G: FieldDoc = FieldDoc {
    key: "physics.gravity.G",
    unit: "m^3 kg^-1 s^-2",
    default: "6.674e-11",
    range: Range::Positive,
    meaning: "gravitational constant; also sets the contact amplitude U0 (Roig03 Eq. 11)",
};

/// `physics.gravity.theta`.
pub const GRAVITY_THETA: FieldDoc = FieldDoc {
    key: "physics.gravity.theta",
    unit: "-",
    default: "0.5",
    range: Range::open_closed(0.0, MAX_THETA),
    meaning: "tree opening angle: a node is used whole beyond side/theta; ignored by \"direct\"",
};

/// `physics.contact.cutoff`.
pub const CONTACT_CUTOFF: FieldDoc = FieldDoc {
    key: "physics.contact.cutoff",
    unit: "-",
    default: "1e-16",
    range: Range::open(0.0, 1.0),
    meaning: "pairs whose contact potential is provably below cutoff x U0 are skipped (also >= 1e-300)",
};

/// `physics.dissipation.F0`.
pub const DISSIPATION_F0: FieldDoc = FieldDoc {
    key: "physics.dissipation.F0",
    unit: "s m^-2",
    default: "required",
    range: Range::NonNegative,
    meaning: "dissipation coefficient (Roig03 Eq. 41), acting on touching pairs only",
};

/// `physics.flyby.mass`.
pub const FLYBY_MASS: FieldDoc = FieldDoc {
    key: "physics.flyby.mass",
    unit: "kg",
    default: "required",
    range: Range::NonNegative,
    meaning: "planet mass (0: no pull, the frame moves in a straight line at v_inf)",
};

/// `physics.flyby.radius`.
pub const FLYBY_RADIUS: FieldDoc = FieldDoc {
    key: "physics.flyby.radius",
    unit: "m",
    default: "none",
    range: Range::Positive,
    meaning: "planet radius: the perigee must lie outside it; the reference radius of j2",
};

/// `physics.flyby.q`.
pub const FLYBY_Q: FieldDoc = FieldDoc {
    key: "physics.flyby.q",
    unit: "m",
    default: "required",
    range: Range::Positive,
    meaning: "perigee distance between the planet's centre and the frame origin",
};

/// `physics.flyby.v_inf`.
pub const FLYBY_V_INF: FieldDoc = FieldDoc {
    key: "physics.flyby.v_inf",
    unit: "m/s",
    default: "(v_inf or eccentricity)",
    range: Range::Positive,
    meaning: "speed at infinity of a hyperbolic flyby; exactly one of v_inf, eccentricity",
};

/// `integrator.rtol`.
pub const RTOL: FieldDoc = FieldDoc {
    key: "integrator.rtol",
    unit: "-",
    default: "1e-10",
    range: Range::closed_open(MIN_RTOL, 1.0),
    meaning: "relative tolerance of the adaptive methods (refused with \"rk4\")",
};

/// `integrator.atol`.
pub const ATOL: FieldDoc = FieldDoc {
    key: "integrator.atol",
    unit: "m, m/s, rad/s",
    default: "1e-10",
    range: Range::NonNegative,
    meaning: "absolute tolerance in each state's own unit (refused with \"rk4\")",
};

/// `body.mass`.
pub const BODY_MASS: FieldDoc = FieldDoc {
    key: "body.mass",
    unit: "kg",
    default: "(mass or density)",
    range: Range::Positive,
    meaning: "mass; exactly one of mass, density",
};

/// `body.density`.
pub const BODY_DENSITY: FieldDoc = FieldDoc {
    key: "body.density",
    unit: "kg/m^3",
    default: "(mass or density)",
    range: Range::Positive,
    meaning: "bulk density: mass = density 4/3 pi A B C",
};

/// Every table of the file.
pub const TABLES: &[TableDoc] = &[
    TableDoc {
        key: "scene",
        array: false,
        meaning: "what is simulated and for how long (required)",
    },
    TableDoc {
        key: "model",
        array: false,
        meaning: "model constants: exactly one of kappa or calibrate (required)",
    },
    TableDoc {
        key: "model.calibrate",
        array: false,
        meaning: "kappa from Roig03 Eq. 14 for the lightest and heaviest body, instead of model.kappa",
    },
    TableDoc {
        key: "physics",
        array: false,
        meaning: "the force terms; an absent term is not computed (absent table: bodies move freely)",
    },
    TableDoc {
        key: "physics.gravity",
        array: false,
        meaning: "monopole gravity between centres of mass (Roig03 Eq. 6); `gravity = {}` turns it on",
    },
    TableDoc {
        key: "physics.contact",
        array: false,
        meaning: "Gaussian-overlap contact potential (Roig03 Eqs. 7-12); `contact = {}` turns it on",
    },
    TableDoc {
        key: "physics.dissipation",
        array: false,
        meaning: "point dissipation (Roig03 Eqs. 40-41)",
    },
    TableDoc {
        key: "physics.flyby",
        array: false,
        meaning: "tide of a planet on a prescribed Kepler orbit (none if absent)",
    },
    TableDoc {
        key: "integrator",
        array: false,
        meaning: "method and tolerances (optional)",
    },
    TableDoc {
        key: "output",
        array: false,
        meaning: "snapshot times and time-series cadence (required)",
    },
    TableDoc {
        key: "body",
        array: true,
        meaning: "one ellipsoid each, body[0], body[1], ... in file order (or scene.bodies_file)",
    },
    crate::io::run_budget::RUN_TABLE,
];

/// Every key of the file, in print order.
pub const FIELDS: &[FieldDoc] = &[
    FieldDoc {
        key: "scene.kind",
        unit: "text",
        default: "required",
        range: Range::Rule("\"ellipsoids\""),
        meaning: "which engine reads the scene",
    },
    T_END,
    FieldDoc {
        key: "scene.seed",
        unit: "count",
        default: "0",
        range: Range::Rule("integer >= 0"),
        meaning: "recorded in summary.json; the model draws no random numbers",
    },
    FieldDoc {
        key: "scene.bodies_file",
        unit: "path",
        default: "none",
        range: Range::Rule("readable CSV, <= 1e7 rows"),
        meaning: "initial bodies (snapshot columns) instead of [[body]], relative to the scene file",
    },
    KAPPA,
    FieldDoc {
        key: "model.inertia",
        unit: "text",
        default: "\"gaussian\"",
        range: Range::Rule("\"gaussian\" | \"uniform\""),
        meaning: "moments of inertia: Roig03 Eq. 4 with the model's kappa, or a uniform ellipsoid",
    },
    CALIBRATE_BETA,
    CALIBRATE_V,
    FieldDoc {
        key: "model.calibrate.reading",
        unit: "text",
        default: "\"printed\"",
        range: Range::Rule("\"printed\" | \"impactor\" | \"reduced\""),
        meaning: "which kinetic energy the barrier is beta times (Roig03 Eq. 13's K)",
    },
    GRAVITY_G,
    FieldDoc {
        key: "physics.gravity.method",
        unit: "text",
        default: "\"auto\"",
        range: Range::Rule("\"auto\" | \"direct\" | \"tree\""),
        meaning: "exact O(N^2) sum, Barnes-Hut tree, or exact below 5000 bodies and tree from there",
    },
    GRAVITY_THETA,
    CONTACT_CUTOFF,
    DISSIPATION_F0,
    FLYBY_MASS,
    FLYBY_RADIUS,
    FLYBY_Q,
    FLYBY_V_INF,
    FieldDoc {
        key: "physics.flyby.eccentricity",
        unit: "-",
        default: "(v_inf or eccentricity)",
        range: Range::Rule(">= 0, != 1; needs mass > 0"),
        meaning: "orbit eccentricity (< 1 elliptic, > 1 hyperbolic); exactly one of v_inf, eccentricity",
    },
    FieldDoc {
        key: "physics.flyby.t_perigee",
        unit: "s",
        default: "required",
        range: Range::Rule("finite"),
        meaning: "time of perigee passage",
    },
    FieldDoc {
        key: "physics.flyby.orientation_deg",
        unit: "deg",
        default: "[0, 0, 0]",
        range: Range::Rule("3 finite numbers"),
        meaning: "[node, inclination, argument of perigee] of the orbit about the planet",
    },
    FieldDoc {
        key: "physics.flyby.j2",
        unit: "-",
        default: "none",
        range: Range::Rule("finite; needs radius"),
        meaning: "the planet's second zonal harmonic (Earth 1.0826e-3)",
    },
    FieldDoc {
        key: "physics.flyby.pole",
        unit: "-",
        default: "[0, 0, 1]",
        range: Range::Rule("3 finite numbers, non-zero"),
        meaning: "the planet's spin axis in the frame (normalised), used with j2",
    },
    FieldDoc {
        key: "integrator.method",
        unit: "text",
        default: "\"bulirsch-stoer\"",
        range: Range::Rule("\"bulirsch-stoer\" | \"dop853\" | \"dopri5\" | \"rk4\" | \"bulirsch-stoer-implicit\""),
        meaning: "adaptive Gragg-Bulirsch-Stoer, Dormand-Prince 8(5,3) or 5(4), fixed-step RK4, or linearly implicit \
                  extrapolation for stiff dissipation (contact damping time well below the contact period; `check` \
                  advises it)",
    },
    RTOL,
    ATOL,
    FieldDoc {
        key: "integrator.step",
        unit: "s",
        default: "required by \"rk4\"",
        range: Range::Rule(">= t_end x 1e-12; \"rk4\" only"),
        meaning: "the fixed step of \"rk4\"",
    },
    FieldDoc {
        key: "integrator.project_attitudes",
        unit: "bool",
        default: "true (false for bulirsch-stoer)",
        range: Range::Rule("true | false"),
        meaning: "pull the attitudes back onto |q| = 1 at every output sample",
    },
    FieldDoc {
        key: "output.times",
        unit: "s",
        default: "[0, t_end]",
        range: Range::Rule("increasing, in [0, t_end], <= 1e5"),
        meaning: "snapshot times (snapshots/<k>.csv); [] = none; not with snapshot_every",
    },
    FieldDoc {
        key: "output.snapshot_every",
        unit: "s",
        default: "none",
        range: Range::Rule(">= 1e-300, <= 1e5 snapshots"),
        meaning: "snapshot cadence instead of times: 0, every, 2 every, ... and t_end",
    },
    FieldDoc {
        key: "output.every",
        unit: "s",
        default: "required",
        range: Range::Rule(">= t_end / 1e8"),
        meaning: "time-series cadence: a row of timeseries.csv every `every` seconds",
    },
    FieldDoc {
        key: "output.track",
        unit: "count",
        default: "[]",
        range: Range::Rule("body indices < number of bodies, each once"),
        meaning: "bodies whose full state is written to tracks.csv at every time-series row",
    },
    FieldDoc {
        key: "output.vtk",
        unit: "bool",
        default: "false",
        range: Range::Rule("true | false"),
        meaning: "also write every snapshot as VTK (vtk/*.vtp, vtk/run.pvd)",
    },
    FieldDoc {
        key: "body.axes",
        unit: "m",
        default: "required",
        range: Range::Rule("[A, B, C], A >= B >= C >= 1e-300"),
        meaning: "semi-axes along the body x, y, z axes",
    },
    BODY_MASS,
    BODY_DENSITY,
    FieldDoc {
        key: "body.position",
        unit: "m",
        default: "required",
        range: Range::Rule(MIN_SEPARATION_RULE),
        meaning: "centre of mass, world frame",
    },
    FieldDoc {
        key: "body.velocity",
        unit: "m/s",
        default: "[0, 0, 0]",
        range: Range::Rule("3 finite numbers"),
        meaning: "centre-of-mass velocity, world frame",
    },
    FieldDoc {
        key: "body.quaternion",
        unit: "-",
        default: "[0, 0, 0, 1]",
        range: Range::Rule("|q| = 1 within 1e-6"),
        meaning: "attitude [alpha, beta, gamma, delta], scalar last; R(q) maps world to body (Roig03 Eq. 21)",
    },
    FieldDoc {
        key: "body.spin_body",
        unit: "rad/s",
        default: "[0, 0, 0]",
        range: Range::Rule("3 finite numbers"),
        meaning: "spin about the body's principal axes (A, B, C); at most one of spin_body, spin_world",
    },
    FieldDoc {
        key: "body.spin_world",
        unit: "rad/s",
        default: "[0, 0, 0]",
        range: Range::Rule("3 finite numbers"),
        meaning: "spin in the world frame (spin_body = R(q) spin_world)",
    },
    crate::io::run_budget::MAX_STEPS_FIELD,
    crate::io::run_budget::MAX_WALL_FIELD,
];

/// The rule of `body.position`, with [`MIN_CENTRE_SEPARATION`] in it.
const MIN_SEPARATION_RULE: &str = "finite; centres >= 0.5 x the smaller C apart";

/// The reference of the ellipsoid scene file.
pub const REFERENCE: SceneReference = SceneReference {
    kind: "ellipsoids",
    tables: TABLES,
    fields: FIELDS,
};

// The numbers written into the words above, held to the constants they restate.
const _: () = assert!(MIN_CENTRE_SEPARATION == 0.5);
const _: () = assert!(TREE_FROM == 5000);
const _: () = assert!(DEFAULT_THETA == 0.5);
