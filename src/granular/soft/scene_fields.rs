//! The field reference of the `kind = "soft-spheres"` scene file (Zhang17's soft-sphere DEM, §2; nominal material of
//! §2.3.3): one row per key of `soft::scene::SoftSceneFile` (with `[spinup]`, `soft::spinup::SpinupSection`; both read
//! their bounds from here), printed by `rubblepile check --explain soft-spheres`. The rows the validator checks a plain
//! range with are named constants it reads its bounds from ([`crate::io::scene_file::Validator::within`]); the rest
//! state the rule the validator's own code applies.

use crate::io::scene_fields::{FieldDoc, Range, SceneReference, TableDoc};

/// The range of a soft-sphere restitution coefficient: (0, 1].
const RESTITUTION: Range = Range::open_closed(0.0, 1.0);

/// `scene.t_end`.
pub const T_END: FieldDoc = FieldDoc {
    key: "scene.t_end",
    unit: "s",
    default: "required",
    range: Range::Positive,
    meaning: "end time; the run takes round(t_end/dt) steps",
};

/// `material.k_n`.
pub const K_N: FieldDoc = FieldDoc {
    key: "material.k_n",
    unit: "N/m",
    default: "required",
    range: Range::Positive,
    meaning: "normal spring constant (k_S = 2/7 k_N); see `rubblepile ssdem advise`",
};

/// `material.eps_n`.
pub const EPS_N: FieldDoc = FieldDoc {
    key: "material.eps_n",
    unit: "-",
    default: "0.55",
    range: RESTITUTION,
    meaning: "normal coefficient of restitution",
};

/// `material.eps_t`.
pub const EPS_T: FieldDoc = FieldDoc {
    key: "material.eps_t",
    unit: "-",
    default: "0.55",
    range: RESTITUTION,
    meaning: "tangential coefficient of restitution",
};

/// `material.mu_s`.
pub const MU_S: FieldDoc = FieldDoc {
    key: "material.mu_s",
    unit: "-",
    default: "1.0",
    range: Range::NonNegative,
    meaning: "sliding friction coefficient",
};

/// `material.mu_t`.
pub const MU_T: FieldDoc = FieldDoc {
    key: "material.mu_t",
    unit: "-",
    default: "1.3",
    range: Range::NonNegative,
    meaning: "twisting friction coefficient",
};

/// `material.mu_r`.
pub const MU_R: FieldDoc = FieldDoc {
    key: "material.mu_r",
    unit: "-",
    default: "1.05",
    range: Range::NonNegative,
    meaning: "rolling friction coefficient",
};

/// `material.beta`.
pub const BETA: FieldDoc = FieldDoc {
    key: "material.beta",
    unit: "-",
    default: "0.5",
    range: Range::NonNegative,
    meaning: "shape parameter (0 = no twisting or rolling resistance)",
};

/// `material.max_start_overlap`.
pub const MAX_START_OVERLAP: FieldDoc = FieldDoc {
    key: "material.max_start_overlap",
    unit: "-",
    default: "0.05",
    range: Range::NonNegative,
    meaning: "largest initial overlap accepted, as a fraction of the smaller radius",
};

/// `gravity.G`.
pub const GRAVITY_G: FieldDoc = FieldDoc {
    key: "gravity.G",
    unit: "m^3 kg^-1 s^-2",
    default: "6.674e-11",
    range: Range::Positive,
    meaning: "gravitational constant of the self-gravity",
};

/// `gravity.theta`.
pub const GRAVITY_THETA: FieldDoc = FieldDoc {
    key: "gravity.theta",
    unit: "-",
    default: "0.5",
    range: Range::open_closed(0.0, 1.0),
    meaning: "tree opening angle; only with self = \"tree\"",
};

/// `wall.radius`.
pub const WALL_RADIUS: FieldDoc = FieldDoc {
    key: "wall.radius",
    unit: "m",
    default: "required by \"sphere\", \"cylinder\"",
    range: Range::Positive,
    meaning: "inner radius of a sphere wall, radius of a cylinder",
};

/// `wall.length`.
pub const WALL_LENGTH: FieldDoc = FieldDoc {
    key: "wall.length",
    unit: "m",
    default: "infinite",
    range: Range::Positive,
    meaning: "length of a cylinder along its axis, centred on its centre",
};

/// `particle.radius`.
pub const PARTICLE_RADIUS: FieldDoc = FieldDoc {
    key: "particle.radius",
    unit: "m",
    default: "required",
    range: Range::Positive,
    meaning: "sphere radius",
};

/// `particle.mass`.
pub const PARTICLE_MASS: FieldDoc = FieldDoc {
    key: "particle.mass",
    unit: "kg",
    default: "(mass or density)",
    range: Range::Positive,
    meaning: "mass; exactly one of mass, density",
};

/// `particle.density`.
pub const PARTICLE_DENSITY: FieldDoc = FieldDoc {
    key: "particle.density",
    unit: "kg/m^3",
    default: "(mass or density)",
    range: Range::Positive,
    meaning: "grain density: mass = 4/3 pi r^3 density",
};

/// `spinup.T_start`.
pub const SPINUP_T_START: FieldDoc = FieldDoc {
    key: "spinup.T_start",
    unit: "h",
    default: "required",
    range: Range::Positive,
    meaning: "spin period held while the body settles",
};

/// `spinup.T_inter`.
pub const SPINUP_T_INTER: FieldDoc = FieldDoc {
    key: "spinup.T_inter",
    unit: "h",
    default: "required",
    range: Range::Positive,
    meaning: "spin period at t_inter (<= T_start)",
};

/// `spinup.T_final`.
pub const SPINUP_T_FINAL: FieldDoc = FieldDoc {
    key: "spinup.T_final",
    unit: "h",
    default: "required",
    range: Range::Positive,
    meaning: "final spin period, held after t_final (<= T_inter)",
};

/// `spinup.t_start`.
pub const SPINUP_TIME_START: FieldDoc = FieldDoc {
    key: "spinup.t_start",
    unit: "s",
    default: "required",
    range: Range::NonNegative,
    meaning: "end of the settling phase",
};

/// `spinup.t_inter`.
pub const SPINUP_TIME_INTER: FieldDoc = FieldDoc {
    key: "spinup.t_inter",
    unit: "s",
    default: "required",
    range: Range::NonNegative,
    meaning: "end of the fast linear spin-up (>= t_start)",
};

/// `spinup.t_final`.
pub const SPINUP_TIME_FINAL: FieldDoc = FieldDoc {
    key: "spinup.t_final",
    unit: "s",
    default: "required",
    range: Range::NonNegative,
    meaning: "end of the slow spin-up (>= t_inter)",
};

/// `spinup.rest_length`.
pub const SPINUP_REST_LENGTH: FieldDoc = FieldDoc {
    key: "spinup.rest_length",
    unit: "s",
    default: "0",
    range: Range::NonNegative,
    meaning: "length of each rest; all rests together shorter than t_final - t_inter",
};

/// `spinup.release_axis_ratio`.
pub const SPINUP_RELEASE_AXIS_RATIO: FieldDoc = FieldDoc {
    key: "spinup.release_axis_ratio",
    unit: "-",
    default: "0.1",
    range: Range::Positive,
    meaning: "disruption when |d(b/a)| or |d(c/a)| exceeds this",
};

/// `spinup.release_packing`.
pub const SPINUP_RELEASE_PACKING: FieldDoc = FieldDoc {
    key: "spinup.release_packing",
    unit: "-",
    default: "0.01",
    range: Range::Positive,
    meaning: "disruption when the interior packing fraction changes by more than this",
};

/// `spinup.interior_depth`.
pub const SPINUP_INTERIOR_DEPTH: FieldDoc = FieldDoc {
    key: "spinup.interior_depth",
    unit: "m",
    default: "none (layer rule)",
    range: Range::NonNegative,
    meaning: "depth below the surface layer from which a particle counts in eta_B (piles of unequal spheres)",
};

/// `spinup.interior_ramp`.
pub const SPINUP_INTERIOR_RAMP: FieldDoc = FieldDoc {
    key: "spinup.interior_ramp",
    unit: "m",
    default: "interior_depth",
    range: Range::Positive,
    meaning: "depth span over which a particle's eta_B weight rises from 0 to 1; needs interior_depth",
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
        meaning: "the fixed leapfrog step (required)",
    },
    TableDoc {
        key: "material",
        array: false,
        meaning: "the contact law's material, Zhang17 Eqs. 1-12 (required for k_n; the rest default to Zhang17's nominal set)",
    },
    TableDoc {
        key: "gravity",
        array: false,
        meaning: "uniform field and self-gravity (optional; absent = no gravity)",
    },
    TableDoc {
        key: "output",
        array: false,
        meaning: "time-series cadence and snapshot times (required)",
    },
    TableDoc {
        key: "wall",
        array: true,
        meaning: "one wall each: a plane (point, normal), the inside of a sphere (centre, radius) or a cylinder (centre, axis, radius, length)",
    },
    crate::granular::vocabulary::OSCILLATION_TABLE,
    TableDoc {
        key: "particle",
        array: true,
        meaning: "one sphere each (or scene.particles_file)",
    },
    TableDoc {
        key: "spinup",
        array: false,
        meaning: "spin-up forcing along a period path T(t) and its diagnostics (optional; Zhang17 §2.3.4)",
    },
    crate::io::run_budget::RUN_TABLE,
];

/// Every key of the file, in print order.
pub const FIELDS: &[FieldDoc] = &[
    FieldDoc {
        key: "scene.kind",
        unit: "text",
        default: "required",
        range: Range::Rule("\"soft-spheres\""),
        meaning: "which engine reads the scene",
    },
    T_END,
    FieldDoc {
        key: "scene.seed",
        unit: "count",
        default: "0",
        range: Range::Rule("integer >= 0"),
        meaning: "recorded in the summary; the engine draws no random numbers",
    },
    FieldDoc {
        key: "scene.particles_file",
        unit: "path",
        default: "none",
        range: Range::Rule("readable CSV, <= 1e7 rows"),
        meaning: "initial particles (t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz) instead of [[particle]]",
    },
    FieldDoc {
        key: "stepping.dt",
        unit: "s",
        default: "required",
        range: Range::Rule("<= 2 sqrt(m_min/2 / k_n) and t_end, >= t_end x 1e-12"),
        meaning: "fixed leapfrog step (see `rubblepile ssdem advise`)",
    },
    K_N,
    EPS_N,
    EPS_T,
    MU_S,
    MU_T,
    MU_R,
    BETA,
    MAX_START_OVERLAP,
    FieldDoc {
        key: "gravity.uniform",
        unit: "m/s^2",
        default: "none",
        range: Range::Rule("3 finite numbers"),
        meaning: "uniform acceleration",
    },
    FieldDoc {
        key: "gravity.self",
        unit: "text",
        default: "none",
        range: Range::Rule("\"tree\" | \"direct\""),
        meaning: "self-gravity by octree (quadrupole) or exact pair sum; absent = none",
    },
    GRAVITY_THETA,
    FieldDoc {
        key: "gravity.interval_steps",
        unit: "steps",
        default: "1",
        range: Range::Rule("integer >= 1; > 1 needs self"),
        meaning: "steps between self-gravity evaluations (r-RESPA kicks)",
    },
    GRAVITY_G,
    FieldDoc {
        key: "output.every",
        unit: "s",
        default: "required",
        range: Range::Rule(">= t_end / 1e8"),
        meaning: "time-series cadence, rounded to whole steps (at least one)",
    },
    FieldDoc {
        key: "output.times",
        unit: "s",
        default: "[0, t_end]",
        range: Range::Rule("increasing, in [0, t_end], >= 1 step apart, <= 1e5"),
        meaning: "snapshot times, each at the nearest step; not with snapshot_every",
    },
    FieldDoc {
        key: "output.snapshot_every",
        unit: "s",
        default: "none",
        range: Range::Rule(">= 1 step, <= 1e5 snapshots"),
        meaning: "snapshot cadence instead of times: 0, every, 2 every, ... and t_end",
    },
    FieldDoc {
        key: "output.vtk",
        unit: "bool",
        default: "false",
        range: Range::Rule("true | false"),
        meaning: "also write every snapshot as VTK (vtk/*.vtp, vtk/run.pvd)",
    },
    FieldDoc {
        key: "wall.kind",
        unit: "text",
        default: "required",
        range: Range::Rule("\"plane\" | \"sphere\" | \"cylinder\""),
        meaning: "a half-space, the inside of a sphere, or a cylinder (touched from inside or outside)",
    },
    FieldDoc {
        key: "wall.point",
        unit: "m",
        default: "required by \"plane\"",
        range: Range::Rule("3 finite numbers"),
        meaning: "a point of the plane",
    },
    FieldDoc {
        key: "wall.normal",
        unit: "-",
        default: "required by \"plane\"",
        range: Range::Rule("3 finite numbers, non-zero"),
        meaning: "plane normal towards the particles (normalised)",
    },
    FieldDoc {
        key: "wall.centre",
        unit: "m",
        default: "required by \"sphere\", \"cylinder\"",
        range: Range::Rule("3 finite numbers"),
        meaning: "centre of a sphere wall, middle of a cylinder's axis",
    },
    FieldDoc {
        key: "wall.axis",
        unit: "-",
        default: "required by \"cylinder\"",
        range: Range::Rule("3 finite numbers, non-zero"),
        meaning: "cylinder axis (normalised)",
    },
    WALL_RADIUS,
    WALL_LENGTH,
    crate::granular::vocabulary::OSCILLATION_AMPLITUDE,
    crate::granular::vocabulary::OSCILLATION_ANGULAR_FREQUENCY,
    crate::granular::vocabulary::OSCILLATION_PHASE,
    FieldDoc {
        key: "wall.oscillation.direction",
        unit: "-",
        default: "normal or axis",
        range: Range::Rule("3 finite numbers, non-zero; required by \"sphere\""),
        meaning: "direction of the oscillation (normalised)",
    },
    FieldDoc {
        range: Range::Rule("finite; \"cylinder\" only"),
        ..crate::granular::vocabulary::WALL_SPIN
    },
    PARTICLE_RADIUS,
    PARTICLE_MASS,
    PARTICLE_DENSITY,
    FieldDoc {
        key: "particle.position",
        unit: "m",
        default: "required",
        range: Range::Rule("3 finite numbers; overlaps <= contact.max_start_overlap"),
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
        meaning: "spin",
    },
    SPINUP_T_START,
    SPINUP_T_INTER,
    SPINUP_T_FINAL,
    SPINUP_TIME_START,
    SPINUP_TIME_INTER,
    SPINUP_TIME_FINAL,
    FieldDoc {
        key: "spinup.rests",
        unit: "count",
        default: "0",
        range: Range::Rule("integer >= 0"),
        meaning: "rest stages in the slow phase",
    },
    SPINUP_REST_LENGTH,
    FieldDoc {
        key: "spinup.axis",
        unit: "-",
        default: "[0, 0, 1]",
        range: Range::Rule("3 finite numbers, non-zero"),
        meaning: "spin axis, fixed in space",
    },
    FieldDoc {
        key: "spinup.target",
        unit: "text",
        default: "\"period\"",
        range: Range::Rule("\"period\" | \"angular_momentum\""),
        meaning: "what the forcing holds on the path: the rotation period, or L = I_ref 2 pi/T(t)",
    },
    SPINUP_RELEASE_AXIS_RATIO,
    SPINUP_RELEASE_PACKING,
    FieldDoc {
        key: "spinup.release_samples",
        unit: "count",
        default: "2",
        range: Range::Rule("integer >= 1"),
        meaning: "consecutive samples beyond a release threshold that confirm disruption",
    },
    FieldDoc {
        key: "spinup.rve_particles",
        unit: "count",
        default: "300",
        range: Range::Rule("integer >= 8"),
        meaning: "target particles per representative volume element (stress diagnostics)",
    },
    SPINUP_INTERIOR_DEPTH,
    SPINUP_INTERIOR_RAMP,
    crate::io::run_budget::MAX_STEPS_FIELD,
    crate::io::run_budget::MAX_WALL_FIELD,
];

/// The reference of the soft-sphere scene file.
pub const REFERENCE: SceneReference = SceneReference {
    kind: "soft-spheres",
    tables: TABLES,
    fields: FIELDS,
};
