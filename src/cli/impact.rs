//! `rubblepile impact`: a projectile (Roig03 Table 2) on a rubble-pile target, run to `t_end` — a thin wrapper
//! around [`rubblepile::impact::run`].
//!
//! The run directory holds, besides the core's outputs, `initial_bodies.csv` (target + projectile in the
//! centre-of-mass frame), `impact.json` (Q, impact time, projectile) and `scene.toml`, an ordinary scene whose
//! `bodies_file` is `initial_bodies.csv`: the same run again is `rubblepile run DIR/scene.toml --out OTHER`.

use std::path::PathBuf;

use crate::cli::common::{CheckpointArgs, CliError, report};
use rubblepile::driver::{RunOptions, run_scene};
use rubblepile::impact::run::{ImpactConfig, ImpactError, prepare_impact, snapshot_times};
use rubblepile::impact::{geometry::ImpactGeometry, pile::ProjectilePile, pile::as_field, projectile::ProjectileSpec};

/// `rubblepile impact`.
#[derive(Debug, clap::Args)]
pub struct ImpactArgs {
    /// Target bodies file (e.g. targets/N200_T4.csv, from `rubblepile target build`).
    #[arg(long)]
    pub target: PathBuf,
    /// Projectile preset P1, P2 or P3 (Roig03 Table 2); or give --projectile-radius-km.
    #[arg(long, default_value = "P2")]
    pub projectile: String,
    /// Equivalent radius of a custom projectile (km); overrides the preset.
    #[arg(long)]
    pub projectile_radius_km: Option<f64>,
    /// Impact speed (km/s).
    #[arg(long, default_value_t = 5.0)]
    pub projectile_speed_km_s: f64,
    /// Angle ζ between the trajectory and the target's spin axis z (degrees, 0–180).
    #[arg(long = "angle-deg", default_value_t = 45.0)]
    pub angle: f64,
    /// Seed of the projectile's attitude.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Impact parameter b (m): the trajectory's offset from the target's centre of mass [default: 0].
    #[arg(long, value_name = "M", conflicts_with_all = ["impact_parameter_frac", "impact_angle_deg"])]
    pub impact_parameter_m: Option<f64>,
    /// b as a fraction (in [0, 1)) of the target's radius R (of its surface ellipsoid's volume).
    #[arg(long, value_name = "F", conflicts_with = "impact_angle_deg")]
    pub impact_parameter_frac: Option<f64>,
    /// Impact angle θ to the surface normal at the aim point (degrees, [0, 90); 0 = head-on); not ζ (--angle-deg).
    #[arg(long, value_name = "DEG")]
    pub impact_angle_deg: Option<f64>,
    /// Azimuth ψ of the aim point around the approach direction n (degrees, [0, 360); 0 along x, 90 along n × x).
    #[arg(long, value_name = "DEG")]
    pub aim_azimuth_deg: Option<f64>,
    /// Spin of the projectile (rad/s, world frame) [default: none].
    #[arg(long, value_name = "X,Y,Z", value_delimiter = ',')]
    pub projectile_spin_rad_s: Option<Vec<f64>>,
    /// Attitude of the projectile: a quaternion, scalar last, world → body [default: random from --seed].
    #[arg(long, value_name = "X,Y,Z,W", value_delimiter = ',')]
    pub projectile_attitude: Option<Vec<f64>>,
    /// Time at which the surfaces first touch (s).
    #[arg(long = "contact-time-s", default_value_t = 90.0)]
    pub contact_time: f64,
    /// End time (s).
    #[arg(long = "t-end-s", default_value_t = 10_000.0)]
    pub t_end: f64,
    /// Relative (and absolute) tolerance: of the whole run for Bulirsch–Stoer (default 1e-6), of each step for
    /// Dop853/Dopri5 (default 1e-8).
    #[arg(long)]
    pub rtol: Option<f64>,
    /// Integrator: bulirsch-stoer (Roig03's), dop853 or dopri5 (these project the attitudes onto |q| = 1 at
    /// every output sample).
    #[arg(long, default_value = "bulirsch-stoer", value_parser = crate::choice::choice::<rubblepile::integrate::Method>())]
    pub method: rubblepile::integrate::Method,
    /// Dissipation coefficient F0 (s m⁻²). The default 1e-6 is Roig03's "F0 ≈ 1" in km and s, and the value
    /// closest to its outcomes in analysis/roig2003/F0_SCAN.md.
    #[arg(long, default_value_t = rubblepile::impact::run::DEFAULT_F0)]
    pub f0: f64,
    /// Inertia model of the ellipsoids: gaussian (Roig03 Eq. 4 with the model's κ) or uniform
    /// (homogeneous ellipsoids, free of the §4.3 spin bias).
    #[arg(long, value_parser = ["gaussian", "uniform"], default_value = "gaussian")]
    pub inertia: String,
    /// β of Roig03 Eq. 14 (κ is calibrated over target + projectile).
    #[arg(long, default_value_t = 10.0)]
    pub beta: f64,
    /// Which kinetic energy K the contact barrier is β times (Roig03 Eq. 13): printed (½ m_l v², Eq. 14 as
    /// printed), impactor (½ m_k v²) or reduced (½ μ v², the pair's collision energy; gives Roig03's
    /// κ ≈ 10). See analysis/roig2003/DISCUSSION.md.
    #[arg(long, default_value_t = rubblepile::ellipsoid::calibration::KappaReading::Printed)]
    pub kappa_reading: rubblepile::ellipsoid::calibration::KappaReading,
    /// Snapshot times (s), comma-separated [default: 0,100,400,1000,10000, cut at --t-end-s, plus --t-end-s].
    #[arg(long = "snapshots-s", value_delimiter = ',')]
    pub snapshots: Option<Vec<f64>>,
    /// Snapshot cadence (s), instead of --snapshots-s: snapshots at 0, S, 2S, … and at --t-end-s (at most 1e5).
    #[arg(long = "snapshot-every-s", value_name = "S", conflicts_with = "snapshots")]
    pub snapshot_every: Option<f64>,
    /// Time-series cadence (s).
    #[arg(long = "every-s", default_value_t = 10.0)]
    pub every: f64,
    /// Output directory (must be empty or absent unless --force).
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite an earlier run in DIR.
    #[arg(long)]
    pub force: bool,
    /// Never show the progress bar.
    #[arg(long)]
    pub no_progress: bool,
    /// Rubble-pile projectile.
    #[command(flatten)]
    pub pile: PileArgs,
    /// Checkpoint options.
    #[command(flatten)]
    pub checkpoints: CheckpointArgs,
}

impl ImpactArgs {
    /// The [`ImpactConfig`] these arguments ask for (errors name the command-line flags).
    pub fn config(&self) -> Result<ImpactConfig, CliError> {
        let speed = self.projectile_speed_km_s * 1e3;
        let projectile = match self.projectile_radius_km {
            Some(r) if r > 0.0 && r.is_finite() => ProjectileSpec::custom("custom".into(), r * 1e3, speed),
            Some(r) => return Err(CliError::usage(format!("--projectile-radius-km: must be > 0, got {r}"))),
            None => {
                let mut p = ProjectileSpec::preset(&self.projectile).ok_or_else(|| {
                    CliError::usage(format!("--projectile: expected P1, P2 or P3, got {}", self.projectile))
                })?;
                p.speed = speed;
                p
            }
        };
        if !(speed > 0.0 && speed.is_finite()) {
            return Err(CliError::usage(format!(
                "--projectile-speed-km-s: must be > 0, got {}",
                self.projectile_speed_km_s
            )));
        }
        let pile = self.pile.read().map_err(cli_error)?;
        let projectile = pile.as_ref().map_or(projectile, |p| p.equivalent_spec(p.id(), speed));
        let a = self;
        let aims = [a.impact_parameter_m, a.impact_parameter_frac, a.impact_angle_deg];
        let (spin, attitude) = (a.projectile_spin_rad_s.as_deref(), a.projectile_attitude.as_deref());
        let geometry = ImpactGeometry::from_options(aims, a.aim_azimuth_deg, spin, attitude).map_err(cli_error)?;
        let cfg = ImpactConfig {
            target: self.target.clone(),
            projectile,
            angle_deg: self.angle,
            seed: self.seed,
            contact_time: self.contact_time,
            t_end: self.t_end,
            method: self.method,
            rtol: self.rtol.unwrap_or(rubblepile::impact::run::default_rtol(self.method)),
            f0: self.f0,
            beta: self.beta,
            kappa_reading: self.kappa_reading,
            snapshots: snapshot_times(self.t_end, self.snapshots.as_deref(), self.snapshot_every)
                .map_err(CliError::usage)?,
            every: self.every,
            inertia: if self.inertia == "uniform" {
                rubblepile::ellipsoid::body::InertiaModel::Uniform
            } else {
                rubblepile::ellipsoid::body::InertiaModel::Gaussian
            },
            pile,
            geometry,
        };
        cfg.validate().map_err(cli_error)?;
        Ok(cfg)
    }
}

/// The command-line flag of each [`ImpactConfig`] field (and of the pile's file) that an [`ImpactError::Invalid`] can
/// name; the custom projectile's fields are all given through its radius.
const FIELD_FLAGS: [(&str, &str); 16] = [
    ("projectile", "--projectile-radius-km"),
    ("projectile.equivalent_radius", "--projectile-radius-km"),
    ("projectile.density", "--projectile-radius-km"),
    ("projectile.axis_ratios", "--projectile-radius-km"),
    ("projectile.speed", "--projectile-speed-km-s"),
    ("projectile_pile", "--projectile-pile"),
    ("angle_deg", "--angle-deg"),
    ("seed", "--seed"),
    ("contact_time", "--contact-time-s"),
    ("t_end", "--t-end-s"),
    ("method", "--method"),
    ("rtol", "--rtol"),
    ("f0", "--f0"),
    ("beta", "--beta"),
    ("snapshots", "--snapshots-s"),
    ("every", "--every-s"),
];

/// The command-line flag of an [`ImpactConfig`] field named in an error ([`FIELD_FLAGS`], else the field with dashes:
/// `impact_angle_deg` is `--impact-angle-deg`), its index kept (`snapshots[2]` is `--snapshots-s[2]`).
fn flag(field: &str) -> String {
    let (head, index) = field.split_at(field.find('[').unwrap_or(field.len()));
    let dashed = || format!("--{}", head.replace('_', "-"));
    let flag = FIELD_FLAGS
        .iter()
        .find(|(f, _)| *f == head)
        .map_or_else(dashed, |p| p.1.into());
    format!("{flag}{index}")
}

/// An impact error as the command line reports it (flags instead of field names).
fn cli_error(e: ImpactError) -> CliError {
    let code = e.exit_code();
    let message = match &e {
        ImpactError::Invalid { field, message } => format!("{}: {message}", flag(field)),
        ImpactError::Target { path, message } => format!("--target {}: {message}", path.display()),
        other => other.to_string(),
    };
    CliError { message, code }
}

/// Runs `impact`: prints the impact's one-line description, then runs it (see [`rubblepile::impact::run`]).
pub fn impact(args: &ImpactArgs) -> Result<(), CliError> {
    let cfg = args.config()?;
    let options = RunOptions {
        force: true,
        ..args.checkpoints.options(!args.no_progress)?
    };
    let prepared = prepare_impact(&cfg, &args.out, args.force).map_err(cli_error)?;
    println!("{}", prepared.plan.title);
    report(run_scene(&prepared.scene, &args.out, &options))
}

/// `--projectile-pile FILE [--pile-fixed-attitude]` of `rubblepile impact`.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct PileArgs {
    /// A rubble-pile projectile: a bodies file such as targets/N30_T4.csv (any N and spin), thrown whole at
    /// --projectile-speed-km-s; replaces --projectile and --projectile-radius-km.
    #[arg(long)]
    pub projectile_pile: Option<PathBuf>,
    /// Keep the projectile pile's orientation of the file instead of a random attitude drawn from --seed.
    #[arg(long, requires = "projectile_pile")]
    pub pile_fixed_attitude: bool,
}

impl PileArgs {
    /// The projectile pile these arguments ask for, if any; a file that cannot be read is
    /// [`ImpactError::Invalid`] with field `projectile_pile`.
    pub fn read(&self) -> Result<Option<ProjectilePile>, ImpactError> {
        self.projectile_pile
            .as_ref()
            .map(|file| ProjectilePile::read(file, !self.pile_fixed_attitude).map_err(as_field("projectile_pile")))
            .transpose()
    }
}

#[cfg(test)]
mod tests {
    /// Every flag of the table is one of `rubblepile impact`'s, and an index follows its field.
    #[test]
    fn field_flags_are_the_command_s_flags() {
        let command = <super::ImpactArgs as clap::Args>::augment_args(clap::Command::new("impact"));
        let longs: Vec<&str> = command.get_arguments().filter_map(|a| a.get_long()).collect();
        assert!(
            super::FIELD_FLAGS.iter().all(|(_, f)| longs.contains(&&f[2..])),
            "{longs:?}"
        );
        assert_eq!(super::flag("snapshots[2]"), "--snapshots-s[2]");
    }
}
