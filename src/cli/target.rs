//! `rubblepile target build`: a relaxed rubble-pile target (Roig03 §3, Table 1) as `NAME.csv` + `NAME.json`.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use crate::cli::common::CliError;
use rubblepile::driver::DEFAULT_CHECKPOINT_EVERY;
use rubblepile::ellipsoid::output::write_snapshot;
use rubblepile::impact::target::{TargetSpec, build_target_resumable};
use rubblepile::impact::target_checkpoint::{BuildCheckpoint, checkpoint_path, read_checkpoint, write_checkpoint};
use rubblepile::io::run_budget::check_wall_seconds;

/// `rubblepile target …`.
#[derive(Debug, clap::Subcommand)]
pub enum TargetCommand {
    /// Build a target: sizes ∝ D^−2.5, Monte-Carlo placement, rigid rotation, relaxation until rigid.
    Build(BuildArgs),
    /// Print Roig03 Table 1 for target reports (NAME.json) beside the paper's values, as Markdown.
    Table(TableArgs),
}

/// `rubblepile target table`.
#[derive(Debug, clap::Args)]
pub struct TableArgs {
    /// Target reports written by `target build` (NAME.json).
    #[arg(required = true)]
    pub reports: Vec<PathBuf>,
}

/// Roig03 Table 1 by number of fragments: total mass (1e18 kg), effective and apparent radius (km),
/// effective and apparent density (g/cm³), porosity, major and equivalent radius of the largest and the
/// smallest fragment (km).
const TABLE1: [(usize, [f64; 10]); 3] = [
    (30, [10.03, 92.76, 107.44, 3.00, 1.93, 0.36, 90.51, 64.00, 22.62, 16.00]),
    (100, [9.99, 92.64, 107.43, 3.00, 1.92, 0.36, 84.85, 60.00, 14.14, 10.00]),
    (200, [10.05, 92.82, 110.10, 3.00, 1.80, 0.40, 83.43, 59.00, 9.89, 7.00]),
];

/// Runs `target table`.
pub fn table(args: &TableArgs) -> Result<(), CliError> {
    let rows = [
        "Total mass [10^18 kg]",
        "Effective radius [km]",
        "Apparent radius [km]",
        "Effective density [g cm^-3]",
        "Apparent density [g cm^-3]",
        "Porosity",
        "Major radius of largest fragment [km]",
        "Equivalent radius of largest fragment [km]",
        "Major radius of smallest fragment [km]",
        "Equivalent radius of smallest fragment [km]",
        "Spin period [h]",
        "Relaxation time [s]",
        "kappa",
    ];
    let mut header = vec!["quantity".to_string()];
    let mut columns: Vec<Vec<String>> = Vec::new();
    for path in &args.reports {
        let text = std::fs::read_to_string(path).map_err(|e| CliError::usage(format!("{}: {e}", path.display())))?;
        let r: rubblepile::impact::target::TargetReport =
            serde_json::from_str(&text).map_err(|e| CliError::usage(format!("{}: {e}", path.display())))?;
        let ours = [
            r.total_mass_kg / 1e18,
            r.effective_radius_m / 1e3,
            r.apparent_radius_m / 1e3,
            r.effective_density_kg_m3 / 1e3,
            r.apparent_density_kg_m3 / 1e3,
            r.porosity,
            r.largest_major_radius_m / 1e3,
            r.largest_equivalent_radius_m / 1e3,
            r.smallest_major_radius_m / 1e3,
            r.smallest_equivalent_radius_m / 1e3,
            r.spin_period_hours,
            r.relaxation_time_s,
            r.kappa,
        ];
        let stem = path
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
        header.push(format!("{stem} (ours)"));
        columns.push(ours.iter().map(|v| format!("{v:.2}")).collect());
        if let Some((_, paper)) = TABLE1.iter().find(|(n, _)| *n == r.fragments) {
            header.push(format!("N{} (Roig03)", r.fragments));
            let mut col: Vec<String> = paper.iter().map(|v| format!("{v:.2}")).collect();
            col.push(format!("{:.0}", r.spec.period_hours));
            col.extend(["–".to_string(), "–".to_string()]);
            columns.push(col);
        }
    }
    println!("| {} |", header.join(" | "));
    println!("|{}|", vec!["---"; header.len()].join("|"));
    for (k, name) in rows.iter().enumerate() {
        let cells: Vec<&str> = columns.iter().map(|c| c[k].as_str()).collect();
        println!("| {name} | {} |", cells.join(" | "));
    }
    Ok(())
}

/// `rubblepile target build`.
#[derive(Debug, clap::Args)]
pub struct BuildArgs {
    /// Number of fragments. 30, 100 and 200 take Roig03 Table 1's extreme radii (64→16, 60→10,
    /// 59→7 km); any other N needs --r-largest-km and --r-smallest-km.
    #[arg(long)]
    pub fragments: usize,
    /// Spin period of the pile (hours).
    #[arg(long = "period-h")]
    pub period_hours: f64,
    /// Seed of every random choice (sizes, positions, attitudes).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The bodies file to write (snapshot columns); `NAME.json` with the Table 1 quantities goes beside it.
    #[arg(long, value_name = "FILE.csv")]
    pub out: PathBuf,
    /// Equivalent radius of the largest fragment (km).
    #[arg(long)]
    pub r_largest_km: Option<f64>,
    /// Equivalent radius of the smallest fragment (km).
    #[arg(long)]
    pub r_smallest_km: Option<f64>,
    /// Total mass (kg).
    #[arg(long = "total-mass-kg")]
    pub total_mass: Option<f64>,
    /// Dissipation coefficient F0 while relaxing (s m⁻²).
    #[arg(long)]
    pub f0: Option<f64>,
    /// Rigidity criterion: a relaxation round ends when the kinetic energy relative to the best-fit rigid
    /// rotation is below this fraction of the total at two successive checks (dimensionless, in (0, 1)).
    #[arg(long, default_value_t = 1e-4)]
    pub rigidity: f64,
    /// Remove the fragments outside the pile's main clump at the end of every relaxation round, before the spin
    /// is reset (large N: fragments thrown onto wide orbits by the collapse; FILE.json counts them)
    #[arg(long)]
    pub drop_detached: bool,
    /// Which K of Roig03 Eq. 13 sets κ: printed, impactor or reduced (the impacts' κ; see `rubblepile impact`)
    #[arg(long, default_value = "printed")]
    pub kappa_reading: rubblepile::ellipsoid::calibration::KappaReading,
    /// Overwrite FILE.csv / FILE.json (and a checkpoint) of an earlier build.
    #[arg(long)]
    pub force: bool,
    /// Continue an interrupted build from `FILE.checkpoint.json` (same options as the interrupted build).
    #[arg(long, conflicts_with = "force")]
    pub resume: bool,
    /// Write `FILE.checkpoint.json` at the first relaxation check after this many wall-clock seconds (s; 0 = at
    /// every check, else 0.001 to 1e7).
    #[arg(long = "checkpoint-every-s", value_name = "SECONDS", default_value_t = DEFAULT_CHECKPOINT_EVERY)]
    pub checkpoint_every: f64,
}

/// Path of the JSON report beside a target CSV.
pub fn report_path(csv: &Path) -> PathBuf {
    csv.with_extension("json")
}

/// Runs `target build`.
pub fn build(args: &BuildArgs) -> Result<(), CliError> {
    let mut spec = TargetSpec::table1_or_sizes(
        args.fragments,
        args.period_hours,
        args.seed,
        args.r_largest_km,
        args.r_smallest_km,
    )
    .map_err(CliError::usage)?;
    if let Some(m) = args.total_mass {
        spec.total_mass = m;
    }
    if let Some(f0) = args.f0 {
        spec.f0 = f0;
    }
    if !(args.rigidity > 0.0 && args.rigidity < 1.0) {
        return Err(CliError::usage(format!(
            "--rigidity: expected a fraction in (0, 1), got {}",
            args.rigidity
        )));
    }
    spec.rigidity = args.rigidity;
    spec.drop_detached = args.drop_detached;
    spec.kappa_reading = args.kappa_reading;
    if args.out.extension().is_none_or(|e| e != "csv") {
        return Err(CliError::usage(format!(
            "--out: expected a path ending in .csv, got {}",
            args.out.display()
        )));
    }
    let json = report_path(&args.out);
    if !args.force && (args.out.exists() || json.exists()) {
        return Err(CliError::usage(format!(
            "--out: {} (or its .json) exists; use --force to overwrite it",
            args.out.display()
        )));
    }
    check_wall_seconds(
        "--checkpoint-every-s",
        args.checkpoint_every,
        "at every relaxation check",
    )
    .map_err(CliError::usage)?;
    let checkpoint_file = checkpoint_path(&args.out);
    let resume = if args.resume {
        Some(read_checkpoint(&checkpoint_file).map_err(CliError::usage)?)
    } else if checkpoint_file.exists() && !args.force {
        return Err(CliError::usage(format!(
            "--out: {} holds an interrupted build; continue it with --resume or start afresh with --force",
            checkpoint_file.display()
        )));
    } else {
        None
    };
    if let Some(dir) = args.out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| CliError::failed(format!("{}: {e}", dir.display())))?;
    }
    let bar = std::io::stderr().is_terminal().then(|| {
        let b = indicatif::ProgressBar::new_spinner();
        b.enable_steady_tick(std::time::Duration::from_millis(200));
        b
    });
    let mut progress = |round: usize, t: f64, fraction: f64, period_h: f64| {
        let line = format!(
            "relaxing: round {round}, t = {t:.0} s, K_rel/K = {fraction:.2e} (target {:.0e}), period {period_h:.3} h",
            spec.rigidity
        );
        // a log file (no terminal) gets one line per check, so a long build can be followed
        match &bar {
            Some(b) => b.set_message(line),
            None => eprintln!("{line}"),
        }
    };
    let started = std::time::Instant::now();
    let mut last_checkpoint = std::time::Instant::now();
    let mut checkpoint_error = None;
    let mut checkpoint = |c: &BuildCheckpoint| {
        if last_checkpoint.elapsed().as_secs_f64() >= args.checkpoint_every && checkpoint_error.is_none() {
            checkpoint_error = write_checkpoint(&checkpoint_file, c).err();
            last_checkpoint = std::time::Instant::now();
        }
    };
    let built = build_target_resumable(&spec, resume, &mut progress, &mut checkpoint);
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if let Some(e) = checkpoint_error {
        eprintln!("warning: could not write {}: {e}", checkpoint_file.display());
    }
    let (bodies, report) = built.map_err(|e| CliError::failed(format!("target build: {e}")))?;
    write_snapshot(&args.out, 0.0, &bodies).map_err(|e| CliError::failed(format!("{}: {e}", args.out.display())))?;
    let text = serde_json::to_string_pretty(&report).map_err(|e| CliError::failed(e.to_string()))?;
    rubblepile::io::safe_write::write_atomic(&json, text + "\n")
        .map_err(|e| CliError::failed(rubblepile::io::safe_write::describe(&json, &e)))?;
    if checkpoint_file.exists() {
        // the build is complete: its checkpoint would only block the next build of this name
        std::fs::remove_file(&checkpoint_file)
            .map_err(|e| CliError::failed(format!("{}: {e}", checkpoint_file.display())))?;
    }
    println!(
        "target: {} fragments, M = {:.4e} kg, R_eff = {:.2} km, R_app = {:.2} km, porosity {:.3}, period {:.3} h, \
         kappa {:.3}; relaxed {:.0} s in {} rounds (K_rel/K = {:.1e}, energy error {:.1e}); wall {:.1} s; wrote {} and {}",
        report.fragments,
        report.total_mass_kg,
        report.effective_radius_m / 1e3,
        report.apparent_radius_m / 1e3,
        report.porosity,
        report.spin_period_hours,
        report.kappa,
        report.relaxation_time_s,
        report.relaxation_rounds,
        report.non_rigid_fraction,
        report.relaxation_energy_error,
        started.elapsed().as_secs_f64(),
        args.out.display(),
        json.display()
    );
    Ok(())
}
