//! `rubblepile flyby`: its flags, read into the library's [`FlybyConfig`].

use std::path::PathBuf;

use super::common::CheckpointArgs;
use rubblepile::impact::flyby::{DEFAULT_START_Q, EARTH_MASS_KG, EARTH_RADIUS_M, FlybyConfig};

/// `rubblepile flyby`: a rubble pile (a target file) past a planet on a hyperbolic orbit.
#[derive(Debug, Clone, clap::Args)]
pub struct FlybyArgs {
    /// Target bodies file (snapshot columns, e.g. from `rubblepile target build`).
    #[arg(long)]
    pub target: PathBuf,
    /// Rescale the pile to this apparent radius (m; max over fragments of |r − r_cm| + A); a rescaled pile is
    /// settled before the run [default: as built].
    #[arg(long)]
    pub radius_m: Option<f64>,
    /// Set the pile into rigid rotation about its z axis with this period (hours); a re-spun pile is settled before
    /// the run [default: the target's spins].
    #[arg(long = "period-h")]
    pub period_hours: Option<f64>,
    /// Planet mass (kg; 0 for a control run without tide, the frame then moves straight at v∞) [default: Earth].
    #[arg(long = "planet-mass-kg", default_value_t = EARTH_MASS_KG)]
    pub planet_mass: f64,
    /// Planet radius (m) [default: Earth's mean radius].
    #[arg(long, default_value_t = EARTH_RADIUS_M)]
    pub planet_radius_m: f64,
    /// The planet's J2 (dimensionless; Earth 1.0826e-3), with `--planet-radius-m` as its reference radius
    /// [default: none, a point mass].
    #[arg(long)]
    pub planet_j2: Option<f64>,
    /// The planet's spin axis X,Y,Z in the run's frame (the flyby orbit lies in the x–y plane), used with
    /// `--planet-j2` [default: 0,0,1].
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub planet_pole: Option<Vec<f64>>,
    /// Perigee distance from the planet's centre (m).
    #[arg(long)]
    pub q_m: f64,
    /// Speed at infinity (km/s).
    #[arg(long, default_value_t = 5.8)]
    pub v_inf_km_s: f64,
    /// Orbit orientation Ω,i,ω (degrees; see `physics.flyby.orientation_deg`) [default: 0,0,0, prograde in x–y].
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub orientation_deg: Option<Vec<f64>>,
    /// Start and end with the planet this many q away.
    #[arg(long, default_value_t = DEFAULT_START_Q)]
    pub start_q: f64,
    /// κ of the pile [default: "kappa" of the target's NAME.json, as built].
    #[arg(long)]
    pub kappa: Option<f64>,
    /// Dissipation F0 (s m⁻²) [default: 1e-6 (100 km/R)², R the pile's apparent radius].
    #[arg(long)]
    pub f0: Option<f64>,
    /// Relative (and absolute) tolerance of Bulirsch–Stoer over the run (and over the settling).
    #[arg(long, default_value_t = 1e-6)]
    pub rtol: f64,
    /// Number of snapshots, evenly spaced from start to end (2 to 100000).
    #[arg(long, default_value_t = 9)]
    pub snapshots: usize,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
    /// Overwrite an earlier run in DIR.
    #[arg(long)]
    pub force: bool,
    /// Write the run directory (scene, bodies) but do not run it (the pile is still settled when it would be).
    #[arg(long)]
    pub no_run: bool,
    /// Skip the control run without the planet (by default it runs into DIR/control over the same time).
    #[arg(long)]
    pub no_control: bool,
    /// After settling, put the pile into rigid rotation about its axis of largest moment with the same |L|
    /// (settles an as-built pile too).
    #[arg(long)]
    pub settle_to_principal: bool,
    /// Cap on the settling time (hours) [default: 100 free-fall times √(3π/(32 G ρ)) of the pile].
    #[arg(long = "settle-max-h")]
    pub settle_max_hours: Option<f64>,
    /// Never show the progress bar (it is shown only when stderr is a terminal anyway).
    #[arg(long)]
    pub no_progress: bool,
    /// Checkpoints, extra snapshot formats (`--format xyz`), progress lines in a batch log (`--progress-every-s`)
    /// and budgets, as for `rubblepile run`; the control run takes the same.
    #[command(flatten)]
    pub checkpoints: CheckpointArgs,
}

impl FlybyArgs {
    /// The library's configuration of these flags.
    pub fn config(&self) -> FlybyConfig {
        let a = self.clone();
        FlybyConfig {
            target: a.target,
            radius_m: a.radius_m,
            period_hours: a.period_hours,
            planet_mass: a.planet_mass,
            planet_radius_m: a.planet_radius_m,
            planet_j2: a.planet_j2,
            planet_pole: a.planet_pole,
            q_m: a.q_m,
            v_inf_km_s: a.v_inf_km_s,
            orientation_deg: a.orientation_deg,
            start_q: a.start_q,
            kappa: a.kappa,
            f0: a.f0,
            rtol: a.rtol,
            snapshots: a.snapshots,
            out: a.out,
            force: a.force,
            no_run: a.no_run,
            no_control: a.no_control,
            settle_to_principal: a.settle_to_principal,
            settle_max_hours: a.settle_max_hours,
        }
    }
}
