//! Impact campaigns: a grid of impact runs (targets × projectiles × angles × seeds, Roig03 §3) from one
//! TOML file, run in parallel, resumable, summarised in `campaign.csv`.
//!
//! # The campaign file
//!
//! ```toml
//! [campaign]
//! out = "../../runs/roig2003"      # campaign directory (required; relative to the campaign file)
//! targets = ["../../targets/N30_T4.csv", "../../targets/N200_T4.csv"]  # bodies files (required, >= 1;
//!                                  # relative to the campaign file; their stems must differ)
//! projectiles = ["P1", "P2", "P3"] # P1/P2/P3 (Roig03 Table 2) or ids of [[projectile]] tables (required)
//! angles = [0.0, 45.0, 90.0]       # ζ between trajectory and spin axis z (degrees, 0-180; required)
//! seeds = [1]                      # seeds of the projectile's attitude (default [1])
//! parallel = 2                     # runs at once (default: the number of cores)
//!
//! [impact]                         # optional; every key optional (defaults of `rubblepile impact`)
//! t_end = 10000.0                  # end time (s; default 10000)
//! rtol = 1e-9                      # Bulirsch-Stoer relative = absolute tolerance (default 1e-9)
//! f0 = 1e-6                        # dissipation coefficient F0 (s m^-2; default 1e-6)
//! beta = 10.0                      # beta of Roig03 Eq. 14 for kappa (default 10)
//! contact_time = 90.0              # time at which the surfaces first touch (s; default 90)
//! every = 10.0                     # time-series cadence (s; default 10)
//! snapshots = [0.0, 100.0]         # snapshot times (s; default 0, 100, 400, 1000, 10000 cut at t_end, + t_end)
//! speed_km_s = 5.0                 # impact speed of P1-P3 and of custom projectiles without one (km/s; default 5)
//! inertia = "gaussian"             # "gaussian" (Roig03 Eq. 4, default) or "uniform" (homogeneous ellipsoids)
//!
//! [[projectile]]                   # optional custom projectiles (density 3000 kg/m^3, axes 1 : 0.7 : 0.5)
//! id = "S1"                        # name in campaign.projectiles and in run names ([A-Za-z0-9_-], not P1-P3)
//! radius_km = 1.0                  # equivalent radius (km)
//! speed_km_s = 0.05                # impact speed (km/s; default impact.speed_km_s)
//! ```
//!
//! Unknown keys are refused; every error is one line naming the field (`campaign.angles[2]: …`). Relative
//! paths are joined to the campaign file's directory and cleaned lexically (`a/b/../../t.csv` → `t.csv`).
//!
//! # The campaign directory
//!
//! One run directory per grid point, `<out>/<target stem>_<projectile>_z<angle>_s<seed>/` (e.g.
//! `N30_T4_P1_z45_s1`), holding what [`crate::impact::run::run_impact`] writes, and `<out>/campaign.csv`,
//! rewritten atomically (`campaign.csv.tmp`, then rename) whenever a run starts or ends, one row per grid
//! point: `run,target,projectile,angle_deg,seed,q_erg_per_g,status,wall_seconds,final_time,steps_accepted,
//! rhs_evaluations,energy_error,linear_momentum_error,angular_momentum_error` (`target` is the target
//! file's stem; `status` is `completed`, `failed: <cause>`, `pending` or `running`; the run's numbers come
//! from its `summary.json` and are empty while there is none).
//!
//! # Resuming
//!
//! What happens to each grid point is decided when the campaign starts ([`Action`]):
//! - its `summary.json` says `completed` → skipped;
//! - otherwise its `checkpoint.json` exists → continued with [`resume_run`] (bit-identical to an
//!   uninterrupted run);
//! - otherwise (no directory, an empty one, a run that died before its first checkpoint, a failed run
//!   without a checkpoint) → started afresh, overwriting the run's files;
//! - a completed or checkpointed run whose `scene.toml` (comments aside) or `initial_bodies.csv` differ
//!   from what this campaign would write (a changed `[impact]`, a rebuilt target) is neither skipped nor
//!   resumed but recorded as failed: its results are left alone; move the directory away to redo it.
//!
//! A failed run is recorded (`failed: <cause>`) and the campaign goes on. The runs are executed by
//! `parallel` plain threads (not a rayon pool, so that each run's own rayon work goes to the global pool
//! instead of stealing whole runs while it waits).

use std::collections::HashSet;
use std::io::{IsTerminal, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use crate::driver::{RunError, RunOptions, RunSummary, resume_run};
use crate::ellipsoid::body::Body;
use crate::ellipsoid::output::read_bodies_csv;
use crate::impact::projectile::ProjectileSpec;
use crate::impact::run::{
    DEFAULT_BETA, DEFAULT_CONTACT_TIME, DEFAULT_EVERY, DEFAULT_F0, DEFAULT_RTOL, DEFAULT_T_END, ImpactConfig,
    ImpactError, ImpactPlan, default_snapshots, read_target, run_impact,
};
use crate::io::checkpoint::CHECKPOINT_FILE;
use crate::io::fmt_f64;

/// Name of the campaign table in the campaign directory.
pub const CAMPAIGN_CSV: &str = "campaign.csv";

/// Columns of `campaign.csv`.
pub const CAMPAIGN_COLUMNS: [&str; 14] = [
    "run",
    "target",
    "projectile",
    "angle_deg",
    "seed",
    "q_erg_per_g",
    "status",
    "wall_seconds",
    "final_time",
    "steps_accepted",
    "rhs_evaluations",
    "energy_error",
    "linear_momentum_error",
    "angular_momentum_error",
];

// ---------------------------------------------------------------------------------------------
// The file.
// ---------------------------------------------------------------------------------------------

/// A campaign file, as written (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignFile {
    /// `[campaign]`: the grid and where it goes.
    pub campaign: CampaignSection,
    /// `[impact]`: overrides of the impact defaults shared by every run.
    #[serde(default)]
    pub impact: ImpactSection,
    /// `[[projectile]]`: custom projectiles.
    #[serde(default, rename = "projectile")]
    pub projectiles: Vec<CustomProjectile>,
}

/// `[campaign]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CampaignSection {
    /// Campaign directory (relative to the campaign file's directory); required.
    pub out: PathBuf,
    /// Target bodies files (relative to the campaign file's directory), at least one; the file stems name
    /// the runs, so they must differ.
    pub targets: Vec<PathBuf>,
    /// Projectiles: `P1`, `P2`, `P3` (Roig03 Table 2; any case) or ids of `[[projectile]]` tables.
    pub projectiles: Vec<String>,
    /// Impact angles ζ (degrees, in [0, 180]).
    pub angles: Vec<f64>,
    /// Seeds of the projectile's attitude (default `[1]`).
    #[serde(default = "default_seeds")]
    pub seeds: Vec<u64>,
    /// Runs at once (≥ 1; default: the number of cores).
    #[serde(default)]
    pub parallel: Option<usize>,
}

fn default_seeds() -> Vec<u64> {
    vec![1]
}

/// `[impact]`: every key optional; absent = the default of [`ImpactConfig::new`].
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImpactSection {
    /// End time (s; default 10 000).
    pub t_end: Option<f64>,
    /// Bulirsch–Stoer relative (= absolute) tolerance (default 1e-9).
    pub rtol: Option<f64>,
    /// Dissipation coefficient F0 (s m⁻²; default 1e-6).
    pub f0: Option<f64>,
    /// β of Roig03 Eq. 14 (default 10).
    pub beta: Option<f64>,
    /// Time at which the surfaces first touch (s; default 90).
    pub contact_time: Option<f64>,
    /// Time-series cadence (s; default 10).
    pub every: Option<f64>,
    /// Snapshot times (s; default 0, 100, 400, 1000, 10 000 cut to `t_end`, plus `t_end`).
    pub snapshots: Option<Vec<f64>>,
    /// Impact speed of P1–P3 and of custom projectiles without their own (km/s; default 5).
    pub speed_km_s: Option<f64>,
    /// Inertia model of the ellipsoids: `"gaussian"` (Roig03 Eq. 4, default) or `"uniform"`.
    pub inertia: Option<crate::ellipsoid::body::InertiaModel>,
}

/// `[[projectile]]`: a custom projectile (density 3000 kg m⁻³, axis ratios 1 : 0.7 : 0.5).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CustomProjectile {
    /// Its name in `campaign.projectiles` and in run names: letters, digits, `_`, `-`; not P1–P3.
    pub id: String,
    /// Equivalent radius (km, > 0).
    pub radius_km: f64,
    /// Impact speed (km/s, > 0; default `impact.speed_km_s`).
    #[serde(default)]
    pub speed_km_s: Option<f64>,
}

/// A bad campaign file, or a campaign directory that cannot be written. Messages are one line.
#[derive(Debug, thiserror::Error)]
pub enum CampaignError {
    /// The campaign file could not be read.
    #[error("{file}: cannot read: {reason}")]
    Read {
        /// The file as named.
        file: String,
        /// The OS error.
        reason: String,
    },
    /// Malformed TOML, an unknown or missing key, a value of the wrong type.
    #[error("{file}: {message}")]
    Syntax {
        /// The file.
        file: String,
        /// One line, with the field and the line.
        message: String,
    },
    /// A value out of range (or a target file that cannot be used).
    #[error("{file}: {field}: {message}")]
    Invalid {
        /// The file.
        file: String,
        /// Dotted path of the field, e.g. `campaign.angles[2]`.
        field: String,
        /// What was expected and what was given.
        message: String,
    },
    /// Writing the campaign directory or `campaign.csv` failed.
    #[error("{}: {source}", .path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

impl CampaignError {
    /// The command line's exit code: 2 for a bad campaign file, 1 for an I/O failure.
    pub fn exit_code(&self) -> u8 {
        match self {
            CampaignError::Io { .. } => 1,
            _ => 2,
        }
    }
}

/// One grid point.
#[derive(Debug, Clone, PartialEq)]
pub struct GridPoint {
    /// Run name = directory name under the campaign directory, e.g. `N30_T4_P1_z45_s1`.
    pub name: String,
    /// The target file's stem.
    pub target: String,
    /// The projectile's id.
    pub projectile: String,
    /// ζ (degrees).
    pub angle_deg: f64,
    /// Seed.
    pub seed: u64,
    /// The impact.
    pub config: ImpactConfig,
    /// The impact set up in memory (what the run directory must hold).
    pub plan: ImpactPlan,
}

/// A validated campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct Campaign {
    /// How the campaign file is named in messages.
    pub name: String,
    /// The campaign directory (resolved).
    pub out: PathBuf,
    /// Runs at once.
    pub parallel: usize,
    /// The grid: targets (outermost), projectiles, angles, seeds (innermost).
    pub points: Vec<GridPoint>,
    /// The file as written.
    pub file: CampaignFile,
}

/// Reads and validates a campaign file; relative paths in it are resolved against its directory.
pub fn load_campaign(path: &Path) -> Result<Campaign, CampaignError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| CampaignError::Read {
        file: name.clone(),
        reason: e.to_string().split_whitespace().collect::<Vec<_>>().join(" "),
    })?;
    let base = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    parse_campaign(&text, &name, &base)
}

/// Parses and validates campaign text; `name` is used in messages, `base_dir` resolves relative paths.
pub fn parse_campaign(text: &str, name: &str, base_dir: &Path) -> Result<Campaign, CampaignError> {
    let file = parse_toml(text, name)?;
    resolve(file, name, base_dir)
}

/// `base.join(rel)` with `.` and `dir/..` removed lexically (for readable paths in messages and files).
fn join_clean(base: &Path, rel: &Path) -> PathBuf {
    use std::path::Component;
    let joined = base.join(rel);
    let mut out: Vec<Component> = Vec::new();
    for c in joined.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    if out.is_empty() {
        PathBuf::from(".")
    } else {
        out.iter().collect()
    }
}

fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

fn parse_toml(text: &str, name: &str) -> Result<CampaignFile, CampaignError> {
    let syntax = |message: String| CampaignError::Syntax {
        file: name.to_string(),
        message,
    };
    let line_of = |span: Option<std::ops::Range<usize>>| {
        span.map(|s| {
            let line = text.as_bytes()[..s.start.min(text.len())]
                .iter()
                .filter(|&&b| b == b'\n')
                .count()
                + 1;
            format!(" (line {line})")
        })
        .unwrap_or_default()
    };
    let de = toml::Deserializer::parse(text)
        .map_err(|e| syntax(format!("{}{}", one_line(e.message()), line_of(e.span()))))?;
    serde_path_to_error::deserialize::<_, CampaignFile>(de).map_err(|e| {
        use serde_path_to_error::Segment;
        let mut path = String::new();
        for seg in e.path().iter() {
            match seg {
                Segment::Seq { index } => path.push_str(&format!("[{index}]")),
                Segment::Map { key } | Segment::Enum { variant: key } => {
                    if !path.is_empty() {
                        path.push('.');
                    }
                    path.push_str(key);
                }
                Segment::Unknown => path.push_str(".?"),
            }
        }
        let inner = e.into_inner();
        let msg = one_line(inner.message());
        let line = line_of(inner.span());
        if let Some(rest) = msg.strip_prefix("unknown field `")
            && let Some(end) = rest.find('`')
        {
            // the path ends with the unknown key; name the table holding it
            let key = &rest[..end];
            let table = path.strip_suffix(key).unwrap_or(&path).trim_end_matches('.');
            let table = if table.is_empty() {
                "the top level".to_string()
            } else {
                format!("[{table}]")
            };
            let expected = rest[end + 1..].trim_start_matches(',').trim();
            let expected = if expected.is_empty() {
                String::new()
            } else {
                format!("; {expected}")
            };
            return syntax(format!("unknown field `{key}` in {table}{expected}{line}"));
        }
        if let Some(rest) = msg.strip_prefix("missing field `")
            && let Some(end) = rest.find('`')
        {
            let key = &rest[..end];
            let full = if path.is_empty() {
                key.to_string()
            } else {
                format!("{path}.{key}")
            };
            return syntax(format!("{full}: missing (required){line}"));
        }
        if path.is_empty() {
            syntax(format!("{msg}{line}"))
        } else {
            syntax(format!("{path}: {msg}{line}"))
        }
    })
}

fn resolve(file: CampaignFile, name: &str, base_dir: &Path) -> Result<Campaign, CampaignError> {
    let invalid = |field: String, message: String| CampaignError::Invalid {
        file: name.to_string(),
        field,
        message,
    };
    let c = &file.campaign;
    let imp = &file.impact;
    if c.out.as_os_str().is_empty() {
        return Err(invalid("campaign.out".into(), "must name a directory, got \"\"".into()));
    }
    let parallel = match c.parallel {
        Some(0) => return Err(invalid("campaign.parallel".into(), "must be at least 1, got 0".into())),
        Some(n) => n,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };

    // [impact]
    let t_end = imp.t_end.unwrap_or(DEFAULT_T_END);
    let speed_km_s = imp.speed_km_s.unwrap_or(5.0);
    if !(speed_km_s.is_finite() && speed_km_s > 0.0) {
        return Err(invalid(
            "impact.speed_km_s".into(),
            format!("must be > 0 km/s and finite, got {speed_km_s}"),
        ));
    }

    // [[projectile]]
    let mut custom: Vec<(String, ProjectileSpec)> = Vec::new();
    for (k, p) in file.projectiles.iter().enumerate() {
        let field = |f: &str| format!("projectile[{k}].{f}");
        let id_ok = !p.id.is_empty()
            && p.id
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-');
        if !id_ok {
            return Err(invalid(
                field("id"),
                format!(
                    "need letters, digits, `_` or `-` (it names run directories), got {:?}",
                    p.id
                ),
            ));
        }
        if ProjectileSpec::preset(&p.id).is_some() || custom.iter().any(|(id, _)| *id == p.id) {
            return Err(invalid(
                field("id"),
                format!(
                    "`{}` is already a projectile (P1-P3 or an earlier [[projectile]])",
                    p.id
                ),
            ));
        }
        if !(p.radius_km.is_finite() && p.radius_km > 0.0) {
            return Err(invalid(
                field("radius_km"),
                format!("must be > 0 km and finite, got {}", p.radius_km),
            ));
        }
        let speed = p.speed_km_s.unwrap_or(speed_km_s);
        if !(speed.is_finite() && speed > 0.0) {
            return Err(invalid(
                field("speed_km_s"),
                format!("must be > 0 km/s and finite, got {speed}"),
            ));
        }
        custom.push((
            p.id.clone(),
            ProjectileSpec::custom(p.id.clone(), p.radius_km * 1e3, speed * 1e3),
        ));
    }

    // [campaign] lists
    if c.targets.is_empty() {
        return Err(invalid(
            "campaign.targets".into(),
            "must list at least one target bodies file, got []".into(),
        ));
    }
    let mut targets: Vec<(String, PathBuf, Vec<Body>)> = Vec::new();
    for (k, rel) in c.targets.iter().enumerate() {
        let field = format!("campaign.targets[{k}]");
        let path = join_clean(base_dir, rel);
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        if stem.is_empty() {
            return Err(invalid(
                field,
                format!("not a file name: {:?}", rel.display().to_string()),
            ));
        }
        if targets.iter().any(|(s, _, _)| *s == stem) {
            return Err(invalid(
                field,
                format!("another target file is also named `{stem}` (its stem names the run directories)"),
            ));
        }
        let bodies = read_target(&path).map_err(|e| invalid(field.clone(), one_line(&e.to_string())))?;
        targets.push((stem, path, bodies));
    }
    if c.projectiles.is_empty() {
        return Err(invalid(
            "campaign.projectiles".into(),
            "must list at least one projectile, got []".into(),
        ));
    }
    let mut projectiles: Vec<ProjectileSpec> = Vec::new();
    for (k, id) in c.projectiles.iter().enumerate() {
        let field = format!("campaign.projectiles[{k}]");
        let p = match (ProjectileSpec::preset(id), custom.iter().find(|(c, _)| c == id)) {
            (Some(mut p), _) => {
                p.speed = speed_km_s * 1e3;
                p
            }
            (None, Some((_, p))) => p.clone(),
            (None, None) => {
                return Err(invalid(
                    field,
                    format!("expected P1, P2, P3 or the id of a [[projectile]] table, got {id:?}"),
                ));
            }
        };
        if projectiles.iter().any(|q| q.id == p.id) {
            return Err(invalid(field, format!("`{}` is listed twice", p.id)));
        }
        projectiles.push(p);
    }
    if c.angles.is_empty() {
        return Err(invalid(
            "campaign.angles".into(),
            "must list at least one angle (degrees), got []".into(),
        ));
    }
    let mut angles: Vec<f64> = Vec::new();
    for (k, &a) in c.angles.iter().enumerate() {
        let field = format!("campaign.angles[{k}]");
        if !(0.0..=180.0).contains(&a) {
            return Err(invalid(field, format!("expected 0 to 180 degrees, got {a}")));
        }
        let a = a + 0.0; // -0 → 0
        if angles.contains(&a) {
            return Err(invalid(field, format!("{a} is listed twice")));
        }
        angles.push(a);
    }
    if c.seeds.is_empty() {
        return Err(invalid(
            "campaign.seeds".into(),
            "must list at least one seed, got []".into(),
        ));
    }
    let mut seen = HashSet::new();
    for (k, s) in c.seeds.iter().enumerate() {
        if !seen.insert(*s) {
            return Err(invalid(format!("campaign.seeds[{k}]"), format!("{s} is listed twice")));
        }
    }

    // The grid; each configuration validated (an error names the campaign's field).
    let mut points = Vec::new();
    for (stem, path, bodies) in &targets {
        for (pk, projectile) in projectiles.iter().enumerate() {
            let mut base = ImpactConfig::new(path.clone(), projectile.clone());
            base.t_end = t_end;
            base.rtol = imp.rtol.unwrap_or(DEFAULT_RTOL);
            base.f0 = imp.f0.unwrap_or(DEFAULT_F0);
            base.beta = imp.beta.unwrap_or(DEFAULT_BETA);
            base.contact_time = imp.contact_time.unwrap_or(DEFAULT_CONTACT_TIME);
            base.every = imp.every.unwrap_or(DEFAULT_EVERY);
            base.inertia = imp.inertia.unwrap_or_default();
            base.snapshots = imp.snapshots.clone().unwrap_or_else(|| default_snapshots(t_end));
            let projectile_field = || match custom.iter().position(|(id, _)| *id == projectile.id) {
                Some(j) => format!("projectile[{j}]"),
                None => format!("campaign.projectiles[{pk}]"),
            };
            base.validate().map_err(|e| match e {
                ImpactError::Invalid { field, message } if field.starts_with("projectile") => {
                    invalid(projectile_field(), format!("{field}: {message}"))
                }
                ImpactError::Invalid { field, message } => invalid(format!("impact.{field}"), message),
                other => invalid("impact".into(), other.to_string()),
            })?;
            base.kappa(bodies).map_err(|e| {
                let message = match e {
                    ImpactError::Invalid { message, .. } => message,
                    other => other.to_string(),
                };
                invalid(projectile_field(), format!("on target `{stem}`: {message}"))
            })?;
            for &angle in &angles {
                for &seed in &c.seeds {
                    let config = ImpactConfig {
                        angle_deg: angle,
                        seed,
                        ..base.clone()
                    };
                    let plan = config.plan(bodies);
                    points.push(GridPoint {
                        name: format!("{stem}_{}_z{angle}_s{seed}", projectile.id),
                        target: stem.clone(),
                        projectile: projectile.id.clone(),
                        angle_deg: angle,
                        seed,
                        config,
                        plan,
                    });
                }
            }
        }
    }
    Ok(Campaign {
        name: name.to_string(),
        out: join_clean(base_dir, &c.out),
        parallel,
        points,
        file,
    })
}

// ---------------------------------------------------------------------------------------------
// Running.
// ---------------------------------------------------------------------------------------------

/// How a campaign runs (not what it runs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CampaignOptions {
    /// Options of every run: the checkpoint cadence and the testing stop (`force` is ignored: a run is
    /// started afresh only as the module docs say); `progress` = the campaign's progress display on stderr
    /// (only when stderr is a terminal). The runs' own progress bars are never shown.
    pub run: RunOptions,
    /// Runs at once, overriding `campaign.parallel`.
    pub parallel: Option<usize>,
    /// Print one line per finished run on stdout.
    pub verbose: bool,
}

impl Default for CampaignOptions {
    /// [`RunOptions::default`], the file's `parallel`, quiet.
    fn default() -> Self {
        CampaignOptions {
            run: RunOptions::default(),
            parallel: None,
            verbose: false,
        }
    }
}

/// What the campaign does with a grid point (decided when it starts; see the module docs).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Action {
    /// Already completed: skipped.
    Skip,
    /// Half finished: continued from its checkpoint.
    Resume,
    /// Started afresh.
    Start,
    /// The directory holds a different run: left alone, recorded as failed.
    Conflict(String),
}

/// Where a grid point stands.
#[derive(Debug, Clone, PartialEq)]
pub enum RunStatus {
    /// Not run yet, or stopped after a checkpoint (it is resumed next time).
    Pending,
    /// Running now.
    Running,
    /// Reached `t_end`.
    Completed,
    /// Failed; the cause.
    Failed(String),
}

impl std::fmt::Display for RunStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RunStatus::Pending => write!(f, "pending"),
            RunStatus::Running => write!(f, "running"),
            RunStatus::Completed => write!(f, "completed"),
            RunStatus::Failed(cause) => write!(f, "failed: {}", one_line(cause)),
        }
    }
}

/// The numbers of a run's `summary.json` that `campaign.csv` shows (`None` = absent or not finite).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RunNumbers {
    /// Wall-clock time of the run (s).
    pub wall_seconds: Option<f64>,
    /// Last time reached (s).
    pub final_time: Option<f64>,
    /// Accepted steps.
    pub steps_accepted: Option<u64>,
    /// Right-hand-side evaluations.
    pub rhs_evaluations: Option<u64>,
    /// Relative energy error.
    pub energy_error: Option<f64>,
    /// Relative linear-momentum error.
    pub linear_momentum_error: Option<f64>,
    /// Relative angular-momentum error.
    pub angular_momentum_error: Option<f64>,
}

impl From<&RunSummary> for RunNumbers {
    fn from(s: &RunSummary) -> Self {
        let finite = |x: f64| x.is_finite().then_some(x);
        RunNumbers {
            wall_seconds: finite(s.wall_seconds),
            final_time: finite(s.final_time),
            steps_accepted: Some(s.steps_accepted),
            rhs_evaluations: Some(s.rhs_evaluations),
            energy_error: finite(s.energy_error),
            linear_momentum_error: finite(s.linear_momentum_error),
            angular_momentum_error: finite(s.angular_momentum_error),
        }
    }
}

impl RunNumbers {
    /// From the text of a `summary.json`, exactly (the numbers are parsed as Rust parses them; `null` and
    /// absent keys give `None`).
    fn from_summary_text(text: &str) -> Self {
        // `"key": value` at the top level of the summary (its keys are unique in the file).
        let raw = |key: &str| -> Option<&str> {
            let start = text.find(&format!("\"{key}\":"))? + key.len() + 3;
            let rest = text[start..].trim_start();
            let end = rest.find([',', '}', '\n']).unwrap_or(rest.len());
            Some(rest[..end].trim())
        };
        let f = |k: &str| raw(k).and_then(|s| s.parse::<f64>().ok()).filter(|x| x.is_finite());
        let u = |k: &str| raw(k).and_then(|s| s.parse::<u64>().ok());
        RunNumbers {
            wall_seconds: f("wall_seconds"),
            final_time: f("final_time"),
            steps_accepted: u("steps_accepted"),
            rhs_evaluations: u("rhs_evaluations"),
            energy_error: f("energy_error"),
            linear_momentum_error: f("linear_momentum_error"),
            angular_momentum_error: f("angular_momentum_error"),
        }
    }
}

/// One grid point after (or during) the campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct RunRecord {
    /// Run name (directory under the campaign directory).
    pub name: String,
    /// What the campaign decided to do with it.
    pub action: Action,
    /// Where it stands.
    pub status: RunStatus,
    /// Whether it stopped after a checkpoint on request ([`RunOptions::stop_after_checkpoints`]).
    pub stopped: bool,
    /// Its summary's numbers, once it has one.
    pub numbers: Option<RunNumbers>,
}

/// What a campaign did.
#[derive(Debug, Clone, PartialEq)]
pub struct CampaignReport {
    /// One record per grid point, in grid order.
    pub runs: Vec<RunRecord>,
    /// Wall-clock time of this campaign invocation (s).
    pub wall_seconds: f64,
}

impl CampaignReport {
    fn count(&self, f: impl Fn(&RunRecord) -> bool) -> usize {
        self.runs.iter().filter(|r| f(r)).count()
    }
    /// Runs completed (including skipped ones).
    pub fn completed(&self) -> usize {
        self.count(|r| r.status == RunStatus::Completed)
    }
    /// Runs failed (including conflicts).
    pub fn failed(&self) -> usize {
        self.count(|r| matches!(r.status, RunStatus::Failed(_)))
    }
    /// Runs skipped as already completed.
    pub fn skipped(&self) -> usize {
        self.count(|r| r.action == Action::Skip)
    }
    /// Runs resumed from a checkpoint.
    pub fn resumed(&self) -> usize {
        self.count(|r| r.action == Action::Resume)
    }
    /// Runs still pending (stopped after a checkpoint on request).
    pub fn pending(&self) -> usize {
        self.count(|r| matches!(r.status, RunStatus::Pending | RunStatus::Running))
    }
    /// The largest energy error of the completed runs, and the run.
    pub fn worst_energy_error(&self) -> Option<(f64, &str)> {
        self.runs
            .iter()
            .filter(|r| r.status == RunStatus::Completed)
            .filter_map(|r| Some((r.numbers?.energy_error?, r.name.as_str())))
            .max_by(|a, b| a.0.total_cmp(&b.0))
    }
    /// The one-line summary printed at the end, e.g. `campaign: 18 runs: 18 completed (6 skipped,
    /// 2 resumed), 0 failed, 0 pending; wall 812.3 s; worst energy error 3.1e-10 (N30_T4_P3_z0_s1)`.
    pub fn one_line(&self) -> String {
        let worst = match self.worst_energy_error() {
            Some((e, name)) => format!("worst energy error {e:.1e} ({name})"),
            None => "no energy error (no completed run)".into(),
        };
        format!(
            "campaign: {} runs: {} completed ({} skipped, {} resumed), {} failed, {} pending; wall {:.1} s; {worst}",
            self.runs.len(),
            self.completed(),
            self.skipped(),
            self.resumed(),
            self.failed(),
            self.pending(),
            self.wall_seconds,
        )
    }
}

/// Whether `dir` holds the run `plan` describes: its `scene.toml` (comment lines aside) and its
/// `initial_bodies.csv` (bit for bit) are those this campaign would write.
fn same_run(dir: &Path, plan: &ImpactPlan) -> Result<(), String> {
    let strip = |s: &str| -> Vec<String> {
        s.lines()
            .filter(|l| !l.trim_start().starts_with('#'))
            .map(|l| l.trim_end().to_string())
            .collect()
    };
    let scene = std::fs::read_to_string(dir.join("scene.toml")).map_err(|e| format!("scene.toml: {e}"))?;
    if strip(&scene) != strip(&plan.scene_toml) {
        return Err("its scene.toml differs from this campaign's (changed [impact] settings?)".into());
    }
    let records = read_bodies_csv(&dir.join("initial_bodies.csv")).map_err(|e| e.to_string())?;
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let same = records.len() == plan.bodies.len()
        && records.iter().zip(&plan.bodies).all(|(r, b)| {
            bits(&[r.mass]) == bits(&[b.shape.mass])
                && bits(&r.axes) == bits(b.shape.axes.as_slice())
                && bits(&r.position) == bits(b.position.as_slice())
                && bits(&r.velocity) == bits(b.velocity.as_slice())
                && bits(&r.quaternion) == bits(b.quaternion.as_slice())
                && bits(&r.spin_body) == bits(b.spin_body.as_slice())
        });
    if !same {
        return Err("its initial_bodies.csv differs from this campaign's (a rebuilt target?)".into());
    }
    Ok(())
}

/// What to do with the run directory `dir` of `plan`, with the completed run's numbers when skipped.
pub fn decide(dir: &Path, plan: &ImpactPlan) -> (Action, Option<RunNumbers>) {
    let text = std::fs::read_to_string(dir.join("summary.json")).ok();
    let completed = text
        .as_deref()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(t).ok())
        .is_some_and(|v| v.get("status").and_then(|s| s.as_str()) == Some("completed"));
    let numbers = text.as_deref().map(RunNumbers::from_summary_text);
    let conflict = |why: String| {
        Action::Conflict(format!(
            "the run directory {} holds a different run: {why}; move it away to redo this run",
            dir.display()
        ))
    };
    if completed {
        return match same_run(dir, plan) {
            Ok(()) => (Action::Skip, numbers),
            Err(why) => (conflict(why), numbers),
        };
    }
    if dir.join(CHECKPOINT_FILE).is_file() {
        return match same_run(dir, plan) {
            Ok(()) => (Action::Resume, None),
            Err(why) => (conflict(why), None),
        };
    }
    (Action::Start, None)
}

/// A number for `campaign.csv`: shortest round-trip form, plain between 1e-4 and 1e15, else with an exponent.
fn fmt_num(x: f64) -> String {
    if x == 0.0 || (1e-4..1e15).contains(&x.abs()) {
        format!("{x}")
    } else {
        fmt_f64(x)
    }
}

/// Writes `campaign.csv` (via `campaign.csv.tmp` and a rename).
fn write_campaign_csv(out: &Path, points: &[GridPoint], runs: &[RunRecord]) -> Result<(), CampaignError> {
    let path = out.join(CAMPAIGN_CSV);
    let tmp = out.join(format!("{CAMPAIGN_CSV}.tmp"));
    let io = |p: &Path| {
        let path = p.to_path_buf();
        move |source| CampaignError::Io { path, source }
    };
    let mut w = csv::Writer::from_writer(Vec::new());
    let to_io = |e: csv::Error| CampaignError::Io {
        path: path.clone(),
        source: std::io::Error::other(e.to_string()),
    };
    w.write_record(CAMPAIGN_COLUMNS).map_err(to_io)?;
    for (p, r) in points.iter().zip(runs) {
        let n = r.numbers.unwrap_or_default();
        let f = |x: Option<f64>| x.map(fmt_num).unwrap_or_default();
        let u = |x: Option<u64>| x.map(|x| x.to_string()).unwrap_or_default();
        w.write_record([
            p.name.clone(),
            p.target.clone(),
            p.projectile.clone(),
            format!("{}", p.angle_deg),
            p.seed.to_string(),
            fmt_num(p.plan.setup.q_erg_per_g),
            r.status.to_string(),
            f(n.wall_seconds),
            f(n.final_time),
            u(n.steps_accepted),
            u(n.rhs_evaluations),
            f(n.energy_error),
            f(n.linear_momentum_error),
            f(n.angular_momentum_error),
        ])
        .map_err(to_io)?;
    }
    let bytes = w.into_inner().map_err(|e| CampaignError::Io {
        path: path.clone(),
        source: std::io::Error::other(e.to_string()),
    })?;
    let mut file = std::fs::File::create(&tmp).map_err(io(&tmp))?;
    file.write_all(&bytes).map_err(io(&tmp))?;
    file.sync_all().map_err(io(&tmp))?;
    drop(file);
    std::fs::rename(&tmp, &path).map_err(io(&path))
}

/// The last `t` in a (growing) `timeseries.csv`, for the progress display.
fn last_time(path: &Path) -> Option<f64> {
    let mut f = std::fs::File::open(path).ok()?;
    let len = f.metadata().ok()?.len();
    f.seek(SeekFrom::Start(len.saturating_sub(4096))).ok()?;
    let mut tail = String::new();
    f.read_to_string(&mut tail).ok()?;
    let complete = &tail[..tail.rfind('\n')?];
    let line = complete.rsplit('\n').next()?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(line.as_bytes());
    reader.records().next()?.ok()?.get(0)?.trim().parse().ok()
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Runs one grid point: its new status, whether it stopped on request, its numbers.
fn execute(
    point: &GridPoint,
    dir: &Path,
    action: &Action,
    options: &RunOptions,
) -> (RunStatus, bool, Option<RunNumbers>) {
    let options = RunOptions {
        force: true,
        progress: false,
        ..*options
    };
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| match action {
        Action::Resume => resume_run(dir, &options).map_err(ImpactError::Run),
        _ => run_impact(&point.config, dir, &options),
    }));
    match result {
        Ok(Ok(summary)) => (RunStatus::Completed, false, Some(RunNumbers::from(&summary))),
        Ok(Err(ImpactError::Run(RunError::Failed { cause, summary, .. }))) => (
            RunStatus::Failed(cause),
            false,
            Some(RunNumbers::from(summary.as_ref())),
        ),
        Ok(Err(ImpactError::Run(RunError::Stopped { .. }))) => (RunStatus::Pending, true, None),
        Ok(Err(e)) => (RunStatus::Failed(e.to_string()), false, None),
        Err(panic) => {
            let what = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "unknown".into());
            (RunStatus::Failed(format!("panic: {what}")), false, None)
        }
    }
}

/// The progress display: a bar of finished runs and a line per active run.
struct Display {
    multi: indicatif::MultiProgress,
    main: indicatif::ProgressBar,
    active: Mutex<Vec<(usize, indicatif::ProgressBar, Instant)>>,
}

impl Display {
    fn new(total: u64, finished: u64) -> Self {
        let multi = indicatif::MultiProgress::with_draw_target(indicatif::ProgressDrawTarget::stderr());
        let main = multi.add(indicatif::ProgressBar::new(total));
        let style = indicatif::ProgressStyle::with_template("[{elapsed_precise}] {wide_bar} {pos}/{len} runs {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
        main.set_style(style);
        main.set_position(finished);
        main.enable_steady_tick(Duration::from_millis(500));
        Display {
            multi,
            main,
            active: Mutex::new(Vec::new()),
        }
    }

    fn start(&self, index: usize, name: &str) {
        let pb = self.multi.add(indicatif::ProgressBar::new_spinner());
        let style = indicatif::ProgressStyle::with_template("  {spinner} {prefix}: {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner());
        pb.set_style(style);
        pb.set_prefix(name.to_string());
        pb.set_message("starting");
        lock(&self.active).push((index, pb, Instant::now()));
    }

    fn finish(&self, index: usize, failed: usize) {
        let mut active = lock(&self.active);
        if let Some(k) = active.iter().position(|(i, _, _)| *i == index) {
            let (_, pb, _) = active.remove(k);
            pb.finish_and_clear();
            self.multi.remove(&pb);
        }
        self.main.inc(1);
        if failed > 0 {
            self.main.set_message(format!("({failed} failed)"));
        }
    }

    fn tick(&self, points: &[GridPoint], out: &Path) {
        for (i, pb, started) in lock(&self.active).iter() {
            let p = &points[*i];
            let t_end = p.config.t_end;
            let elapsed = started.elapsed().as_secs();
            let when = format!("{}:{:02}:{:02}", elapsed / 3600, elapsed / 60 % 60, elapsed % 60);
            match last_time(&out.join(&p.name).join("timeseries.csv")) {
                Some(t) => pb.set_message(format!("t = {t:.0}/{t_end} s ({:.0} %), {when}", 100.0 * t / t_end)),
                None => pb.set_message(format!("starting, {when}")),
            }
            pb.tick();
        }
    }

    fn println(&self, line: &str) {
        self.multi.suspend(|| println!("{line}"));
    }
}

/// Runs `campaign` (see the module docs): creates its directory, decides what to do with each grid point,
/// writes `campaign.csv`, runs what needs running with `parallel` runs at once, rewriting `campaign.csv`
/// whenever a run starts or ends. Failed runs are recorded, not returned: the error is only for the
/// campaign directory or `campaign.csv` that cannot be written.
pub fn run_campaign(campaign: &Campaign, options: &CampaignOptions) -> Result<CampaignReport, CampaignError> {
    let started = Instant::now();
    let out = &campaign.out;
    std::fs::create_dir_all(out).map_err(|source| CampaignError::Io {
        path: out.clone(),
        source,
    })?;
    let points = &campaign.points;
    let mut runs = Vec::with_capacity(points.len());
    for p in points {
        let (action, numbers) = decide(&out.join(&p.name), &p.plan);
        let status = match &action {
            Action::Skip => RunStatus::Completed,
            Action::Conflict(why) => RunStatus::Failed(why.clone()),
            Action::Resume | Action::Start => RunStatus::Pending,
        };
        runs.push(RunRecord {
            name: p.name.clone(),
            action,
            status,
            stopped: false,
            numbers,
        });
    }
    write_campaign_csv(out, points, &runs)?;
    let todo: Vec<usize> = (0..runs.len())
        .filter(|&i| matches!(runs[i].action, Action::Resume | Action::Start))
        .collect();
    let finished_before = (runs.len() - todo.len()) as u64;
    let display = (options.run.progress && std::io::stderr().is_terminal() && !todo.is_empty())
        .then(|| Display::new(runs.len() as u64, finished_before));
    let say = |line: String| {
        if options.verbose {
            match &display {
                Some(d) => d.println(&line),
                None => println!("{line}"),
            }
        }
    };
    for r in &runs {
        if let Action::Conflict(why) = &r.action {
            say(format!("{}: failed: {why}", r.name));
        }
    }
    let state = Mutex::new((runs, None::<CampaignError>));
    let next = AtomicUsize::new(0);
    let done_count = AtomicUsize::new(0);
    let all_done = AtomicBool::new(false);
    let parallel = options
        .parallel
        .unwrap_or(campaign.parallel)
        .max(1)
        .min(todo.len().max(1));

    std::thread::scope(|s| {
        let ticker = display.as_ref().map(|d| {
            s.spawn(|| {
                while !all_done.load(Ordering::Relaxed) {
                    d.tick(points, out);
                    std::thread::sleep(Duration::from_millis(250));
                }
            })
        });
        let workers: Vec<_> = (0..parallel)
            .map(|_| {
                s.spawn(|| {
                    loop {
                        let k = next.fetch_add(1, Ordering::SeqCst);
                        let Some(&i) = todo.get(k) else { break };
                        let point = &points[i];
                        let action = {
                            let mut st = lock(&state);
                            st.0[i].status = RunStatus::Running;
                            if let Err(e) = write_campaign_csv(out, points, &st.0) {
                                st.1.get_or_insert(e);
                            }
                            st.0[i].action.clone()
                        };
                        if let Some(d) = &display {
                            d.start(i, &point.name);
                        }
                        let (status, stopped, numbers) = execute(point, &out.join(&point.name), &action, &options.run);
                        let n = done_count.fetch_add(1, Ordering::SeqCst) + 1;
                        let line = match (&status, &numbers) {
                            (RunStatus::Completed, Some(x)) => format!(
                                "completed, wall {:.1} s, energy error {:.1e}",
                                x.wall_seconds.unwrap_or(f64::NAN),
                                x.energy_error.unwrap_or(f64::NAN)
                            ),
                            (RunStatus::Pending, _) if stopped => "stopped after a checkpoint (pending)".into(),
                            (s, _) => s.to_string(),
                        };
                        let failed = {
                            let mut st = lock(&state);
                            let r = &mut st.0[i];
                            r.status = status;
                            r.stopped = stopped;
                            if numbers.is_some() {
                                r.numbers = numbers;
                            }
                            if let Err(e) = write_campaign_csv(out, points, &st.0) {
                                st.1.get_or_insert(e);
                            }
                            st.0.iter().filter(|r| matches!(r.status, RunStatus::Failed(_))).count()
                        };
                        if let Some(d) = &display {
                            d.finish(i, failed);
                        }
                        say(format!("[{n}/{}] {}: {line}", todo.len(), point.name));
                    }
                })
            })
            .collect();
        for w in workers {
            let _ = w.join();
        }
        all_done.store(true, Ordering::Relaxed);
        if let Some(t) = ticker {
            let _ = t.join();
        }
    });
    if let Some(d) = &display {
        d.main.finish_and_clear();
        let _ = d.multi.clear();
    }
    let (runs, error) = state.into_inner().unwrap_or_else(|e| e.into_inner());
    if let Some(e) = error {
        return Err(e);
    }
    Ok(CampaignReport {
        runs,
        wall_seconds: started.elapsed().as_secs_f64(),
    })
}
