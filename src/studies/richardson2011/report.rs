//! `rubblepile report richardson2011`: regenerates `analysis/richardson2011/REPORT.md` and its figures from the
//! model-atmosphere runs (Richardson11 §3.1, [`super::atmosphere`]) and the tumbler runs (§3.2,
//! [`super::tumbler`]), with the paper's numbers beside ours. Hand-written, measured notes (speed, run
//! commands) come from `NOTES.md` in the output directory and are appended verbatim.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::atmosphere::{AtmosphereRun, KS_FRACTIONS, analyse_atmosphere_run};
use super::tumbler::{CO_ROTATION_TOLERANCE, TumblerRun, analyse_tumbler_run};
use rubblepile::analysis::figures::lines::{LineChart, Mark, Series};
use rubblepile::analysis::figures::style::write_figure;
use rubblepile::math::mean_std;

/// Richardson11 §3.1: expected scale heights for masses 1, 3, 10.
const PAPER_SCALE_HEIGHTS: [f64; 3] = [1.88, 0.626, 0.188];
/// Richardson11 §3.1: KS probabilities of the final snapshot, masses 1, 3, 10.
const PAPER_FINAL_KS: [f64; 3] = [0.89, 0.08, 0.70];

/// What the Richardson11 report reads and where it writes (the options of `rubblepile report richardson2011`).
#[derive(Debug, Clone, PartialEq)]
pub struct Richardson2011Inputs {
    /// Model-atmosphere run directory in the radius-1.0 cylinder.
    pub atmosphere: PathBuf,
    /// The same in the half-radius cylinder, if run.
    pub half: Option<PathBuf>,
    /// Tumbler run directories, one per Froude number.
    pub tumbler: Vec<PathBuf>,
    /// Where REPORT.md and figures/ go (NOTES.md there is appended to the report).
    pub out: PathBuf,
}

/// Why the report could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// A run directory could not be read or analysed (the caller's input).
    #[error("{0}")]
    Input(String),
    /// A figure or the report could not be written.
    #[error("{0}")]
    Output(String),
}

impl ReportError {
    /// Whether the error is the caller's (bad input) rather than a failure to write.
    pub fn is_input(&self) -> bool {
        matches!(self, ReportError::Input(_))
    }
}

fn species_name(m: f64) -> String {
    format!("m = {m}")
}

fn atmosphere_figures(run: &AtmosphereRun, tag: &str, fig_dir: &Path) -> Result<Vec<String>, String> {
    let mut made = Vec::new();
    let mut series = Vec::new();
    for (s, &m) in run.masses.iter().enumerate() {
        series.push(Series {
            label: format!("{}: mean height", species_name(m)),
            points: run.snapshots.iter().map(|p| (p.t, p.mean_heights[s])).collect(),
            errors: Vec::new(),
            colour: s,
            mark: Mark::Line,
        });
        let (t0, t1) = (run.snapshots[0].t, run.snapshots.last().map_or(0.0, |p| p.t));
        series.push(Series {
            label: format!("{}: kT/(m g) = {:.3}", species_name(m), run.expected[s]),
            points: vec![(t0, run.expected[s]), (t1, run.expected[s])],
            errors: Vec::new(),
            colour: s,
            mark: Mark::Dashed,
        });
    }
    let chart = LineChart {
        title: format!(
            "Model atmosphere, cylinder radius {}: mean heights (cf. Richardson11 Fig. 5)",
            run.cylinder_radius
        ),
        x_label: "time (system units)".into(),
        y_label: "mean height above the plane (system units)".into(),
        series,
        log_x: false,
    };
    made.extend(write_figure(fig_dir, &format!("{tag}_mean_heights"), &chart)?);
    // KS curves of the last snapshot: empirical cumulative distribution and the exponential model, vs z/h.
    let mut series = Vec::new();
    for (s, &m) in run.masses.iter().enumerate() {
        let mut z = run.final_heights[s].clone();
        z.sort_by(f64::total_cmp);
        let h = rubblepile::math::mean(&z);
        let n = z.len() as f64;
        series.push(Series {
            label: format!("{}: heights", species_name(m)),
            points: z
                .iter()
                .enumerate()
                .map(|(k, &v)| (v / h, (k as f64 + 1.0) / n))
                .collect(),
            errors: Vec::new(),
            colour: s,
            mark: Mark::Line,
        });
    }
    let x_max = 6.0;
    series.push(Series {
        label: "1 − exp(−z/h), h = mean height".into(),
        points: (0..=120)
            .map(|k| {
                let x = x_max * k as f64 / 120.0;
                (x, 1.0 - (-x).exp())
            })
            .collect(),
        errors: Vec::new(),
        colour: 3,
        mark: Mark::Dashed,
    });
    let chart = LineChart {
        title: format!(
            "KS curves at t = {:.0} (cf. Richardson11 Fig. 6)",
            run.ks.last().map_or(0.0, |k| k.t)
        ),
        x_label: "height / mean height of the species".into(),
        y_label: "cumulative fraction".into(),
        series,
        log_x: false,
    };
    made.extend(write_figure(fig_dir, &format!("{tag}_ks_curves"), &chart)?);
    let chart = LineChart {
        title: "Model atmosphere: total energy".into(),
        x_label: "time (system units)".into(),
        y_label: "(E − E0) / |E0|".into(),
        series: vec![Series {
            label: format!("cylinder radius {}", run.cylinder_radius),
            points: run.energy_series.clone(),
            errors: Vec::new(),
            colour: 0,
            mark: Mark::Line,
        }],
        log_x: false,
    };
    made.extend(write_figure(fig_dir, &format!("{tag}_energy"), &chart)?);
    Ok(made)
}

fn atmosphere_section(md: &mut String, run: &AtmosphereRun, title: &str, paper: bool) {
    let t_last = run.snapshots.last().map_or(f64::NAN, |p| p.t);
    let _ = writeln!(md, "### {title}\n");
    let _ = writeln!(
        md,
        "Run `{}`: {} particles ({}), t = 0…{t_last} in {} steps, {} collisions, {:.1} s wall ({:.3e} events/s), \
         largest overlap at a collision {:.1e} of a radius.\n",
        run.dir.display(),
        run.counts.iter().sum::<usize>(),
        run.masses
            .iter()
            .zip(&run.counts)
            .map(|(m, n)| format!("{n} of mass {m}"))
            .collect::<Vec<_>>()
            .join(", "),
        run.steps,
        run.collisions,
        run.wall_seconds,
        run.events_per_second,
        run.max_overlap
    );
    let _ = writeln!(
        md,
        "Energy above the ground state (every particle resting on the plane) at t = 0: E = {:.2}; kT = (2/5) E/N = \
         {:.4}; its relative change by the end: {:.1e}.\n",
        run.energy0, run.kt, run.energy_drift
    );
    let _ = writeln!(
        md,
        "| mass | kT/(m g) (ours) | paper's expected | mean height, 50–100 % of the run (± 1σ over snapshots) | ratio to kT/(m g) | KS p, last snapshot | paper, last snapshot |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|");
    for (s, &m) in run.masses.iter().enumerate() {
        let (mh, sd) = run.late_mean_heights[s];
        let last = run.ks.last().map_or(f64::NAN, |k| k.p_measured[s]);
        let _ = writeln!(
            md,
            "| {m} | {:.3} | {} | {mh:.3} ± {sd:.3} | {:.2} | {last:.2} | {} |",
            run.expected[s],
            if paper {
                format!("{}", PAPER_SCALE_HEIGHTS.get(s).copied().unwrap_or(f64::NAN))
            } else {
                "—".into()
            },
            mh / run.expected[s],
            if paper {
                format!("{}", PAPER_FINAL_KS.get(s).copied().unwrap_or(f64::NAN))
            } else {
                "—".into()
            },
        );
    }
    let _ = writeln!(
        md,
        "\nKS probabilities (statrs, two-sided asymptotic) of each species' heights against 1 − exp(−z/h), at the \
         snapshots nearest {} of the run; first with h = the snapshot's mean height (the paper's choice), then with h = \
         kT/(m g):\n",
        KS_FRACTIONS
            .iter()
            .map(|f| format!("{:.0} %", 100.0 * f))
            .collect::<Vec<_>>()
            .join(", ")
    );
    let _ = writeln!(
        md,
        "| t | {} |",
        run.masses
            .iter()
            .map(|m| format!("p (m = {m}), h = mean | p (m = {m}), h = kT/(m g)"))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    let _ = writeln!(md, "|---|{}", "---|---|".repeat(run.masses.len()));
    for k in &run.ks {
        let cells: Vec<String> = (0..run.masses.len())
            .map(|s| format!("{:.3} | {:.3}", k.p_measured[s], k.p_expected[s]))
            .collect();
        let _ = writeln!(md, "| {:.0} | {} |", k.t, cells.join(" | "));
    }
    let means: Vec<String> = (0..run.masses.len())
        .map(|s| {
            let (m, sd) = mean_std(&run.ks.iter().map(|k| k.p_measured[s]).collect::<Vec<_>>());
            format!("m = {}: {m:.2} ± {sd:.2}", run.masses[s])
        })
        .collect();
    let _ = writeln!(
        md,
        "\nMean KS probability (h = mean height) over these snapshots: {}.\n",
        means.join("; ")
    );
}

/// Tumbler runs grouped by their starting fill (to 0.01), in order of fill, each group in order of Fr.
fn by_fill(runs: &[TumblerRun]) -> Vec<(f64, Vec<&TumblerRun>)> {
    let mut groups: Vec<(f64, Vec<&TumblerRun>)> = Vec::new();
    for r in runs {
        match groups.iter_mut().find(|g| (g.0 - r.fill).abs() < 0.005) {
            Some(g) => g.1.push(r),
            None => groups.push((r.fill, vec![r])),
        }
    }
    groups.sort_by(|a, b| a.0.total_cmp(&b.0));
    groups
}

fn tumbler_table(md: &mut String, runs: &[TumblerRun]) {
    let _ = writeln!(
        md,
        "| Fr | fill (free particles) | R/r_in | ω (rad/s) | status | t reached (s) | turns | angle (deg) | snapshots fitted | co-rotating, 50–75 % / 75–100 % | Ω/ω, 50–75 % / 75–100 % | above axis | collisions | events/s | wall (s) |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for r in runs {
        let [a, b] = r.late_halves;
        let _ = writeln!(
            md,
            "| {:.3} | {:.2} ({}) | {:.2} | {:.3} | {} | {:.2} | {:.1} | {:.1} ± {:.1} | {} | {:.2} / {:.2} | {:.2} / {:.2} | {:.2} | {} | {:.2e} | {:.0} |",
            r.froude,
            r.fill,
            r.free,
            r.threshold,
            r.omega,
            r.status,
            r.t_reached,
            r.t_reached * r.omega / std::f64::consts::TAU,
            r.angle.0,
            r.angle.1,
            r.angles.len(),
            a.co_rotating,
            b.co_rotating,
            a.spin_ratio,
            b.spin_ratio,
            r.late.above_axis,
            r.collisions,
            r.events_per_second,
            r.wall_seconds
        );
    }
}

fn angle_chart(groups: &[(f64, Vec<&TumblerRun>)], r_over_d: f64) -> LineChart {
    let series = groups
        .iter()
        .enumerate()
        .map(|(k, (fill, g))| {
            let ok: Vec<&&TumblerRun> = g.iter().filter(|r| !r.angles.is_empty()).collect();
            Series {
                label: format!("this work, R/d = {r_over_d:.0}, fill {fill:.2}"),
                points: ok.iter().map(|r| (r.froude, r.angle.0)).collect(),
                errors: ok.iter().map(|r| r.angle.1).collect(),
                colour: k,
                mark: Mark::Points,
            }
        })
        .collect();
    LineChart {
        title: "Tumbler: dynamic angle of repose vs Froude number (cf. Richardson11 Fig. 8)".into(),
        x_label: "Fr = ω² R / g".into(),
        y_label: "dynamic angle of repose (deg)".into(),
        series,
        log_x: true,
    }
}

fn centrifuging_chart(groups: &[(f64, Vec<&TumblerRun>)]) -> LineChart {
    let mut series = Vec::new();
    for (k, (fill, g)) in groups.iter().enumerate() {
        series.push(Series {
            label: format!("fill {fill:.2}: co-rotating fraction"),
            points: g.iter().map(|r| (r.froude, r.late.co_rotating)).collect(),
            errors: Vec::new(),
            colour: 2 * k,
            mark: Mark::Points,
        });
        series.push(Series {
            label: format!("fill {fill:.2}: Ω/ω"),
            points: g.iter().map(|r| (r.froude, r.late.spin_ratio)).collect(),
            errors: Vec::new(),
            colour: 2 * k + 1,
            mark: Mark::Points,
        });
        let threshold = g.first().map_or(f64::NAN, |r| r.threshold);
        series.push(Series {
            label: format!("fill {fill:.2}: R/r_in = {threshold:.2}"),
            points: vec![(threshold, 0.0), (threshold, 1.0)],
            errors: Vec::new(),
            colour: 2 * k,
            mark: Mark::Dashed,
        });
    }
    LineChart {
        title: "Tumbler: centrifuging vs Froude number (second half of each run)".into(),
        x_label: "Fr = ω² R / g".into(),
        y_label: "co-rotating fraction; mean angular velocity / ω".into(),
        series,
        log_x: true,
    }
}

fn tumbler_section(md: &mut String, runs: &[TumblerRun], fig_dir: &Path) -> Result<Vec<String>, String> {
    let _ = writeln!(md, "## Tumbler (Richardson11 §3.2)\n");
    let Some(first) = runs.first() else {
        let _ = writeln!(md, "No tumbler runs given.\n");
        return Ok(Vec::new());
    };
    let r_over_d = first.radius / (2.0 * first.particle_radius);
    let _ = writeln!(
        md,
        "Drum radius R = {} m, free particles of radius {} m (R/d = {r_over_d:.1}; the paper: 6513 particles, R/d ≈ \
         57), {} stuck to the drum (its rough lining, turning with it). Dynamic angle: straight-line fit to the surface \
         points with −0.8 R < x < 0 (the rising side, the paper's \"left of centre\"), mean ± 1σ over the snapshots \
         of the second half of each run.\n",
        first.radius, first.particle_radius, first.stuck
    );
    let _ = writeln!(
        md,
        "Centrifuging (`src/studies/richardson2011/tumbler.rs`, means over the snapshots of 50–75 % and 75–100 % of each run): \
         \"co-rotating\" is the fraction of free particles whose velocity differs from the drum's rigid rotation at \
         their position by less than {:.0} % of the local drum speed ω ρ (1 for a bed turning with the drum, 0 at \
         rest); Ω/ω is their angular momentum about the axis over that of rigid co-rotation at their positions; \
         \"above axis\" the fraction above the axis over 50–100 % (0 for a half-full bed below the axis, 0.5 for a \
         uniform ring). Fill: the fraction of the disc inside the lining (radius R − 2r) below the top of the bed at \
         t = 0. R/r_in: the Froude number at which a bed of that fill spread into an annulus against the lining, inner \
         radius r_in = (R − 2r) √(1 − fill), is held at the top down to its inner surface (ω² r_in ≥ g).\n",
        100.0 * CO_ROTATION_TOLERANCE
    );
    tumbler_table(md, runs);
    let groups = by_fill(runs);
    let mut made = Vec::new();
    if runs.iter().any(|r| !r.angles.is_empty()) {
        made.extend(write_figure(
            fig_dir,
            "tumbler_angle_vs_froude",
            &angle_chart(&groups, r_over_d),
        )?);
    }
    made.extend(write_figure(
        fig_dir,
        "tumbler_centrifuging_vs_froude",
        &centrifuging_chart(&groups),
    )?);
    let _ = writeln!(md);
    Ok(made)
}

/// Analyses the runs and writes `REPORT.md` and its figures; returns the report's path and the number of figure files.
pub fn write_report(args: &Richardson2011Inputs) -> Result<(PathBuf, usize), ReportError> {
    let fig_dir = args.out.join("figures");
    let full = analyse_atmosphere_run(&args.atmosphere).map_err(|e| ReportError::Input(e.to_string()))?;
    let half = match &args.half {
        Some(d) => Some(analyse_atmosphere_run(d).map_err(|e| ReportError::Input(e.to_string()))?),
        None => None,
    };
    let mut tumblers = Vec::new();
    for d in &args.tumbler {
        tumblers.push(analyse_tumbler_run(d).map_err(|e| ReportError::Input(e.to_string()))?);
    }
    // Grouped by fill (as in the figures), then by Fr and run length.
    let key = |r: &TumblerRun| ((r.fill * 100.0).round() as i64, r.froude, r.t_reached);
    tumblers.sort_by(|a, b| {
        let (ka, kb) = (key(a), key(b));
        ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1)).then(ka.2.total_cmp(&kb.2))
    });
    let mut md = String::new();
    let _ = writeln!(md, "# Richardson et al. (2011) hard-sphere DEM — reproduction\n");
    let _ = writeln!(
        md,
        "Generated by `rubblepile report richardson2011 --atmosphere {}{}{} --out {}` (do not edit by hand: the \
         hand-written part is `NOTES.md`, appended at the end). Engine: `src/granular/hard/`; analysis: \
         `src/studies/richardson2011/atmosphere.rs`, `src/studies/richardson2011/tumbler.rs`.\n",
        args.atmosphere.display(),
        args.half
            .as_ref()
            .map_or(String::new(), |h| format!(" --half {}", h.display())),
        if args.tumbler.is_empty() {
            String::new()
        } else {
            format!(
                " --tumbler {}",
                args.tumbler
                    .iter()
                    .map(|d| d.display().to_string())
                    .collect::<Vec<_>>()
                    .join(" ")
            )
        },
        args.out.display()
    );
    let _ = writeln!(md, "## Model atmosphere (Richardson11 §3.1)\n");
    let _ = writeln!(
        md,
        "Heights are those of the bottom surfaces above the plane (z − R). kT = (2/5) E/N from equipartition, E = the \
         total energy above the ground state (Σ ½ m v² + ½ I ω² + m g (z − R)), taken at t = 0 (conserved). The \
         paper's expected 1.88, 0.626, 0.188 correspond to kT = 1.88, i.e. E ≈ 4658 for N = 991; the paper's starting \
         energy was lost in extraction. Its mean KS probabilities over 50…100 % of the run were also lost; only the \
         final-snapshot values 0.89, 0.08, 0.70 survive.\n"
    );
    let mut figures = atmosphere_figures(&full, "atmosphere_r1", &fig_dir).map_err(ReportError::Output)?;
    atmosphere_section(
        &mut md,
        &full,
        &format!("Cylinder radius {}", full.cylinder_radius),
        true,
    );
    if let Some(h) = &half {
        figures.extend(atmosphere_figures(h, "atmosphere_r05", &fig_dir).map_err(ReportError::Output)?);
        atmosphere_section(
            &mut md,
            h,
            &format!("Cylinder radius {} (half as wide)", h.cylinder_radius),
            false,
        );
    }
    figures.extend(tumbler_section(&mut md, &tumblers, &fig_dir).map_err(ReportError::Output)?);
    let _ = writeln!(md, "## Figures\n");
    for f in figures.iter().filter(|f| f.ends_with(".png")) {
        let _ = writeln!(md, "![{f}](figures/{f})");
    }
    crate::studies::report_notes::append_notes(&mut md, &args.out);
    let path = args.out.join("REPORT.md");
    std::fs::write(&path, md).map_err(|e| ReportError::Output(format!("{}: {e}", path.display())))?;
    Ok((path, figures.len()))
}
