//! The field reference of the `kind = "hard-spheres"` scene file (Richardson11's hard spheres with predicted
//! collisions, §2): one row per key of `hard::scene::HardSceneFile` (which reads its bounds from here), printed by
//! `rubblepile check --explain hard-spheres`. The rows the validator checks a plain range with are named
//! constants it reads its bounds from ([`crate::io::scene_file::Validator::within`]); the rest state the rule the
//! validator's own code applies.

use crate::io::scene_fields::{FieldDoc, Range, SceneReference, TableDoc};
use crate::io::scene_file::MAX_EVENTS_PER_STEP;

/// The range of a normal coefficient of restitution: [0, 1].
const NORMAL_RESTITUTION: Range = Range::closed(0.0, 1.0);

/// The range of a tangential coefficient of restitution: [−1, 1] (1 smooth, −1 perfectly rough).
const TANGENTIAL_RESTITUTION: Range = Range::closed(-1.0, 1.0);

/// `scene.t_end`.
pub const T_END: FieldDoc = FieldDoc {
    key: "scene.t_end",
    unit: "s",
    default: "required",
    range: Range::Positive,
    meaning: "end time of the run; it starts at t = 0",
};

/// `stepping.collapse_speed`.
pub const COLLAPSE_SPEED: FieldDoc = FieldDoc {
    key: "stepping.collapse_speed",
    unit: "m/s",
    default: "0 (off)",
    range: Range::NonNegative,
    meaning: "inelastic-collapse guard: slower normal approaches bounce elastically",
};

/// `stepping.max_events_per_step`.
pub const MAX_EVENTS: FieldDoc = FieldDoc {
    key: "stepping.max_events_per_step",
    unit: "count",
    default: "1e7",
    range: Range::closed(1.0, MAX_EVENTS_PER_STEP as f64),
    meaning: "most events one step may process; beyond it the run stops as stalled",
};

/// `stepping.skin_steps`.
pub const SKIN_STEPS: FieldDoc = FieldDoc {
    key: "stepping.skin_steps",
    unit: "steps",
    default: "16",
    range: Range::NonNegative,
    meaning: "neighbour-list skin, about skin_steps |v| dt per particle; 0 = a fresh list every step",
};

/// `material.eps_n`.
pub const MATERIAL_EPS_N: FieldDoc = FieldDoc {
    key: "material.eps_n",
    unit: "-",
    default: "1 (elastic)",
    range: NORMAL_RESTITUTION,
    meaning: "normal coefficient of restitution of every particle",
};

/// `material.eps_t`.
pub const MATERIAL_EPS_T: FieldDoc = FieldDoc {
    key: "material.eps_t",
    unit: "-",
    default: "1 (smooth)",
    range: TANGENTIAL_RESTITUTION,
    meaning: "tangential coefficient of restitution of every particle",
};

/// `particle.mass`.
pub const PARTICLE_MASS: FieldDoc = FieldDoc {
    key: "particle.mass",
    unit: "kg",
    default: "required",
    range: Range::Positive,
    meaning: "mass",
};

/// `particle.radius`.
pub const PARTICLE_RADIUS: FieldDoc = FieldDoc {
    key: "particle.radius",
    unit: "m",
    default: "required",
    range: Range::Positive,
    meaning: "radius",
};

/// `particle.eps_n`.
pub const PARTICLE_EPS_N: FieldDoc = FieldDoc {
    key: "particle.eps_n",
    unit: "-",
    default: "material.eps_n",
    range: NORMAL_RESTITUTION,
    meaning: "this particle's eps_n; a pair uses the mean of its two values",
};

/// `particle.eps_t`.
pub const PARTICLE_EPS_T: FieldDoc = FieldDoc {
    key: "particle.eps_t",
    unit: "-",
    default: "material.eps_t",
    range: TANGENTIAL_RESTITUTION,
    meaning: "this particle's eps_t",
};

/// `wall.eps_n`.
pub const WALL_EPS_N: FieldDoc = FieldDoc {
    key: "wall.eps_n",
    unit: "-",
    default: "the particle's",
    range: NORMAL_RESTITUTION,
    meaning: "eps_n of collisions with this wall",
};

/// `wall.eps_t`.
pub const WALL_EPS_T: FieldDoc = FieldDoc {
    key: "wall.eps_t",
    unit: "-",
    default: "the particle's",
    range: TANGENTIAL_RESTITUTION,
    meaning: "eps_t of collisions with this wall",
};

/// Every table of the file.
pub const TABLES: &[TableDoc] = &[
    TableDoc {
        key: "scene",
        array: false,
        meaning: "what is simulated and for how long (required)",
    },
    TableDoc {
        key: "stepping",
        array: false,
        meaning: "the kick-drift-kick step and the event guards (required)",
    },
    TableDoc {
        key: "gravity",
        array: false,
        meaning: "uniform field (optional; absent = none)",
    },
    TableDoc {
        key: "material",
        array: false,
        meaning: "restitution of every particle unless its own table overrides it (optional)",
    },
    TableDoc {
        key: "output",
        array: false,
        meaning: "snapshot times and time-series cadence (required)",
    },
    TableDoc {
        key: "particle",
        array: true,
        meaning: "one sphere each (or scene.particles_file)",
    },
    TableDoc {
        key: "wall",
        array: true,
        meaning: "one wall each: plane, disk, cylinder, ring, point or line, possibly moving",
    },
    crate::granular::vocabulary::OSCILLATION_TABLE,
    crate::io::run_budget::RUN_TABLE,
];

/// Every key of the file, in print order.
pub const FIELDS: &[FieldDoc] = &[
    FieldDoc {
        key: "scene.kind",
        unit: "text",
        default: "required",
        range: Range::Rule("\"hard-spheres\""),
        meaning: "which engine reads the scene",
    },
    T_END,
    FieldDoc {
        key: "scene.seed",
        unit: "count",
        default: "0",
        range: Range::Rule("integer >= 0"),
        meaning: "recorded in summary.json; the engine draws no random numbers",
    },
    FieldDoc {
        key: "scene.particles_file",
        unit: "path",
        default: "none",
        range: Range::Rule("readable CSV, <= 1e7 rows"),
        meaning: "initial particles (t,id,mass,radius,x,...,wz[,stuck_to]) instead of [[particle]]",
    },
    FieldDoc {
        key: "stepping.dt",
        unit: "s",
        default: "required",
        range: Range::Rule(">= t_end x 1e-12"),
        meaning: "kick-drift-kick step, shortened to land on output times",
    },
    COLLAPSE_SPEED,
    MAX_EVENTS,
    SKIN_STEPS,
    FieldDoc {
        key: "gravity.uniform",
        unit: "m/s^2",
        default: "required",
        range: Range::Rule("3 finite numbers"),
        meaning: "uniform acceleration",
    },
    MATERIAL_EPS_N,
    MATERIAL_EPS_T,
    FieldDoc {
        key: "output.times",
        unit: "s",
        default: "[0, t_end]",
        range: Range::Rule("increasing, in [0, t_end], <= 1e5"),
        meaning: "snapshot times (snapshots/<k>.csv); not with snapshot_every",
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
        meaning: "time-series cadence (timeseries.csv rows)",
    },
    FieldDoc {
        key: "output.vtk",
        unit: "bool",
        default: "false",
        range: Range::Rule("true | false"),
        meaning: "also write every snapshot as VTK (vtk/*.vtp, vtk/run.pvd)",
    },
    PARTICLE_MASS,
    PARTICLE_RADIUS,
    FieldDoc {
        key: "particle.position",
        unit: "m",
        default: "required",
        range: Range::Rule("3 finite numbers; overlaps <= 1e-3 of the radius"),
        meaning: "centre",
    },
    FieldDoc {
        key: "particle.velocity",
        unit: "m/s",
        default: "[0, 0, 0]",
        range: Range::Rule("3 finite numbers"),
        meaning: "velocity",
    },
    FieldDoc {
        key: "particle.spin",
        unit: "rad/s",
        default: "[0, 0, 0]",
        range: Range::Rule("3 finite numbers"),
        meaning: "spin, world frame",
    },
    PARTICLE_EPS_N,
    PARTICLE_EPS_T,
    FieldDoc {
        key: "particle.stuck_to",
        unit: "count",
        default: "free",
        range: Range::Rule("a wall index"),
        meaning: "wall this particle is attached to from t = 0 (moves rigidly with it)",
    },
    FieldDoc {
        key: "wall.kind",
        unit: "text",
        default: "required",
        range: Range::Rule("plane | disk | cylinder | ring | point | line"),
        meaning: "the wall's shape",
    },
    FieldDoc {
        key: "wall.point",
        unit: "m",
        default: "[0, 0, 0]",
        range: Range::Rule("3 finite numbers; plane only"),
        meaning: "a point of the plane at t = 0",
    },
    FieldDoc {
        key: "wall.normal",
        unit: "-",
        default: "[0, 0, 1]",
        range: Range::Rule("3 finite numbers, non-zero; plane only"),
        meaning: "plane normal (normalised)",
    },
    FieldDoc {
        key: "wall.centre",
        unit: "m",
        default: "[0, 0, 0]",
        range: Range::Rule("3 finite numbers; not a plane"),
        meaning: "centre at t = 0 of a disk, ring or point; middle of a cylinder's or line's axis",
    },
    FieldDoc {
        key: "wall.axis",
        unit: "-",
        default: "[0, 0, 1]",
        range: Range::Rule("3 finite numbers, non-zero; not a plane"),
        meaning: "disk/ring normal, cylinder/line axis (normalised)",
    },
    FieldDoc {
        key: "wall.radius",
        unit: "m",
        default: "required by disk, ring, cylinder",
        range: Range::Rule(">= 1e-300 (disk); 0 or >= 1e-300 (ring, cylinder)"),
        meaning: "radius; a ring of 0 is a point, a cylinder of 0 a line",
    },
    FieldDoc {
        key: "wall.length",
        unit: "m",
        default: "infinite",
        range: Range::Rule("0 or >= 1e-300; cylinder, line"),
        meaning: "length centred on centre; a cylinder of length 0 is a ring",
    },
    FieldDoc {
        key: "wall.velocity",
        unit: "m/s",
        default: "[0, 0, 0]",
        range: Range::Rule("3 finite numbers"),
        meaning: "constant translation velocity",
    },
    crate::granular::vocabulary::OSCILLATION_AMPLITUDE,
    crate::granular::vocabulary::OSCILLATION_ANGULAR_FREQUENCY,
    crate::granular::vocabulary::OSCILLATION_PHASE,
    FieldDoc {
        key: "wall.oscillation.direction",
        unit: "-",
        default: "normal or axis",
        range: Range::Rule("3 finite numbers, non-zero"),
        meaning: "direction of the oscillation (normalised)",
    },
    crate::granular::vocabulary::WALL_SPIN,
    WALL_EPS_N,
    WALL_EPS_T,
    FieldDoc {
        key: "wall.sticky",
        unit: "bool",
        default: "false",
        range: Range::Rule("true | false; not with absorbing"),
        meaning: "particles that touch it stay attached and move with it",
    },
    FieldDoc {
        key: "wall.absorbing",
        unit: "bool",
        default: "false",
        range: Range::Rule("true | false"),
        meaning: "particles that touch it are removed and counted",
    },
    crate::io::run_budget::MAX_STEPS_FIELD,
    crate::io::run_budget::MAX_WALL_FIELD,
];

/// The reference of the hard-sphere scene file.
pub const REFERENCE: SceneReference = SceneReference {
    kind: "hard-spheres",
    tables: TABLES,
    fields: FIELDS,
};

// The numbers written into the words above, held to the constants they restate.
const _: () = assert!(crate::granular::hard::stepper::DEFAULT_SKIN_STEPS == 16.0);
