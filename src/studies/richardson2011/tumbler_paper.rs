//! `rubblepile report richardson2011-tumbler RUNS…`: the tumbler of Richardson11 §3.2 at the paper's own scale
//! (particle radius 0.53 mm, lining inner edge at R = 30 mm, 5945 free particles; `make_tumbler.py --scale paper`),
//! written as `TUMBLER_PAPER.md` beside `REPORT.md` with the figure of the dynamic angle of repose against the
//! Froude number (cf. Richardson11 Fig. 8) and the angle of each run against time. A separate verb, because the
//! main report needs the model-atmosphere runs as well; the measurements are those of [`super::tumbler`].
//!
//! Fr here is `ω² R / g` with R the inner edge of the lining, `wall radius − 2 r` (30 mm at the paper's scale: its
//! cylinder was 31.06 mm "to allow for the finite diameter of the stuck particles").

use std::fmt::Write as _;
use std::path::PathBuf;

use super::tumbler::{TumblerRun, analyse_tumbler_run, write_tumbler_compact};
use rubblepile::analysis::AnalysisError;
use rubblepile::analysis::figures::lines::{LineChart, Mark, Series};
use rubblepile::analysis::figures::style::write_figure;
use rubblepile::math::mean_std;

/// Richardson11 §4 (discussion): Pohlman et al. (2006) measured 16.9° for low-friction chrome-steel beads, "within a
/// few degrees of our expected results" at their Froude number (whose value was lost in extraction).
pub const POHLMAN_ANGLE_DEG: f64 = 16.9;

/// The Froude number from which the bed centrifuges (Richardson11 §3.2: "for Fr = 1.0 … centrifuging has begun").
/// The paper estimates a slope only for the subcritical cases, so runs at or above it get no angle in the table or
/// in the Fig. 8 chart (a line fitted to a bed spread round the lining is not a slope), only the centrifuging
/// measures.
pub const CENTRIFUGING_FROUDE: f64 = 1.0;

/// Whether a run is subcritical (`Fr < CENTRIFUGING_FROUDE`), i.e. has a slope to compare with Fig. 8.
pub fn has_slope(run: &TumblerRun) -> bool {
    lining_froude(run) < CENTRIFUGING_FROUDE - 1e-9
}

/// The report's file name in the output directory.
pub const TUMBLER_PAPER_FILE: &str = "TUMBLER_PAPER.md";

/// Options of `rubblepile report richardson2011-tumbler`.
#[derive(Debug, Clone, clap::Args)]
pub struct TumblerPaperArgs {
    /// Tumbler run directories at the paper's scale (finished, or stopped: then read from their time series).
    #[arg(required = true, value_name = "DIR")]
    pub runs: Vec<PathBuf>,
    /// Where TUMBLER_PAPER.md and figures/ go.
    #[arg(long, value_name = "DIR", default_value = "analysis/richardson2011")]
    pub out: PathBuf,
    /// Also write a compact copy of each run (two small CSV files) into DIR/<run name>/, from which this report
    /// regenerates without the snapshots (pass those directories as the runs).
    #[arg(long, value_name = "DIR")]
    pub compact: Option<PathBuf>,
}

/// Fr = ω² R / g with R the lining's inner edge (wall radius − 2 r), the paper's definition at its scale: the run's
/// `froude` (taken with the wall radius) scaled by `(R_wall − 2 r) / R_wall`.
pub fn lining_froude(run: &TumblerRun) -> f64 {
    run.froude * (run.radius - 2.0 * run.particle_radius) / run.radius
}

/// The run's restitution, and "smooth drum" when no particle is stuck to the wall (Richardson11 §3.2's aside:
/// the drum then drives the bed by its surface friction alone), so that such runs get series of their own.
fn restitution_label(run: &TumblerRun) -> String {
    drum_label(run.restitution(), run.stuck)
}

/// [`restitution_label`] of restitution `(ε_n, ε_t)` with `stuck` particles on the wall.
fn drum_label(restitution: (f64, f64), stuck: usize) -> String {
    let drum = if stuck == 0 { ", smooth drum" } else { "" };
    format!("ε_n = {}, ε_t = {}{drum}", restitution.0, restitution.1)
}

fn angle_chart(runs: &[TumblerRun]) -> LineChart {
    let mut labels: Vec<String> = Vec::new();
    let mut series: Vec<Series> = Vec::new();
    for run in runs.iter().filter(|r| !r.angles.is_empty() && has_slope(r)) {
        let label = format!("this work, R/r = {:.0}, {}", run.radius_ratio(), restitution_label(run));
        let k = labels.iter().position(|l| *l == label).unwrap_or_else(|| {
            labels.push(label.clone());
            series.push(Series {
                label,
                points: Vec::new(),
                errors: Vec::new(),
                colour: labels.len() - 1,
                mark: Mark::Points,
            });
            labels.len() - 1
        });
        series[k].points.push((lining_froude(run), run.angle.0));
        series[k].errors.push(run.angle.1);
    }
    let xs: Vec<f64> = series.iter().flat_map(|s| s.points.iter().map(|p| p.0)).collect();
    let (lo, hi) = xs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
    if lo.is_finite() {
        series.push(Series {
            label: format!(
                "Pohlman et al. 2006 via Richardson11 §4: {POHLMAN_ANGLE_DEG}° (their Fr lost in extraction)"
            ),
            points: vec![(lo / 1.5, POHLMAN_ANGLE_DEG), (hi * 1.5, POHLMAN_ANGLE_DEG)],
            errors: Vec::new(),
            colour: labels.len(),
            mark: Mark::Dashed,
        });
    }
    LineChart {
        title: "Tumbler at the paper's scale: dynamic angle of repose vs Froude number (cf. Richardson11 Fig. 8)"
            .into(),
        x_label: "Fr = ω² R / g (R = 30 mm, the lining's inner edge)".into(),
        y_label: "dynamic angle of repose (deg), mean ± 1σ over snapshots".into(),
        series,
        log_x: true,
    }
}

fn time_chart(runs: &[TumblerRun]) -> LineChart {
    let series = runs
        .iter()
        .enumerate()
        .map(|(k, run)| Series {
            label: format!("Fr = {:.3}, {}", lining_froude(run), restitution_label(run)),
            points: run.angle_history.iter().map(|h| (h.0, h.1)).collect(),
            errors: run.angle_history.iter().map(|h| h.2).collect(),
            colour: k,
            mark: Mark::Points,
        })
        .collect();
    LineChart {
        title: "Tumbler at the paper's scale: fitted surface angle per snapshot (whole run)".into(),
        x_label: "time (s)".into(),
        y_label: "surface angle (deg) ± fit error".into(),
        series,
        log_x: false,
    }
}

/// The report's markdown for analysed `runs` (in the given order); `command` is the line that generated it.
pub fn tumbler_paper_markdown(runs: &[TumblerRun], command: &str) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Richardson11 tumbler at the paper's scale (§3.2, Fig. 8)\n");
    let _ = writeln!(
        md,
        "Generated by `{command}` (do not edit by hand; the discussion is in `NOTES.md`). Analysis: \
         `src/studies/richardson2011/tumbler.rs`, `src/studies/richardson2011/tumbler_paper.rs`.\n"
    );
    if let Some(first) = runs.first() {
        let r = first.particle_radius;
        let lining = first.radius - 2.0 * r;
        let _ = writeln!(
            md,
            "Drum wall radius {:.5} m, particle radius {r} m, so the lining's inner edge sits at R = {lining:.5} m \
             (R/r = {:.1}, R/d = {:.1}); {} free particles, {} stuck to the wall (the rough lining). The paper: wall \
             31.06 mm, R = 30 mm, 6513 particles of which 568 stuck (5945 free), \"R/d ≈ 57\" (which matches R/r). \
             Fr = ω² R / g with this R. Angle: straight-line fit to the surface points with −0.8 R_wall < x < 0 (the \
             rising side), one per snapshot in the second half of each run's time reached; the table gives the mean \
             ± 1σ over those snapshots, the mean fit error of one snapshot's angle (the slope's standard error carried \
             through atan), and the means over the first and second halves of that window (equal when settled).\n",
            first.radius,
            first.radius_ratio(),
            first.radius_ratio() / 2.0,
            first.free,
            first.stuck,
        );
    }
    let _ = writeln!(
        md,
        "| Fr | ε_n | ε_t | ω (rad/s) | status | t reached (s) | turns | angle (deg) | snapshots | fit error of one angle (deg) | angle, 1st / 2nd half of window (deg) | last snapshot: t (s), angle ± fit error (deg) | above axis | co-rotating | dt (s) | energy residual | collisions | events/s | wall (s) |"
    );
    let _ = writeln!(
        md,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for run in runs {
        let a: Vec<f64> = run.angles.iter().map(|p| p.1).collect();
        let half = a.len() / 2;
        let (first_half, second_half) = (mean_std(&a[..half]).0, mean_std(&a[half..]).0);
        // Past the centrifuging threshold every angle cell is a dash: the fitted lines are not slopes.
        let (angle, halves, last) = if has_slope(run) {
            (
                format!("{:.1} ± {:.1}", run.angle.0, run.angle.1),
                format!("{first_half:.1} / {second_half:.1}"),
                run.angle_history
                    .last()
                    .map_or("—".to_string(), |h| format!("{:.3}, {:.1} ± {:.1}", h.0, h.1, h.2)),
            )
        } else {
            (
                format!("— (Fr ≥ {CENTRIFUGING_FROUDE}: no slope)"),
                "—".into(),
                "—".into(),
            )
        };
        let _ = writeln!(
            md,
            "| {:.3} | {} | {} | {:.3} | {} | {:.3} | {:.2} | {angle} | {} | {:.1} | {halves} | {last} | {:.2} | {:.2} | {:.3e} | {:.1e} | {} | {:.2e} | {:.0} |",
            lining_froude(run),
            run.eps_n,
            run.eps_t,
            run.omega,
            run.status,
            run.t_reached,
            run.t_reached * run.omega / std::f64::consts::TAU,
            a.len(),
            mean_std(&run.angle_fit_errors).0,
            run.late.above_axis,
            run.late.co_rotating,
            run.dt,
            run.energy_error,
            run.collisions,
            run.events_per_second,
            run.wall_seconds
        );
    }
    let _ = writeln!(
        md,
        "\nThe paper's comparison points, as far as its text gives them: Fig. 8's simulated angles and Brucks et al. \
         (2007, their Fig. 3, R = 30 mm) experimental angles are shown only in the figure, no number survives in the \
         text; the text says the experimental slopes are systematically larger than the simulated ones with a similar \
         trend in Fr, and that Brucks' R = 45 mm drum gives slopes about 10° higher than R = 30 mm. The one number: \
         Pohlman et al. (2006), {POHLMAN_ANGLE_DEG}° for low-friction chrome-steel beads, \"within a few degrees of our \
         expected results\" at their Froude number (lost in extraction), drawn as the dashed line.\n"
    );
    let _ = writeln!(
        md,
        "![tumbler_paper_angle_vs_froude.png](figures/tumbler_paper_angle_vs_froude.png)"
    );
    let _ = writeln!(
        md,
        "![tumbler_paper_angle_vs_time.png](figures/tumbler_paper_angle_vs_time.png)"
    );
    md
}

/// `report richardson2011-tumbler`: [`write_tumbler_paper_report`], saying where it wrote.
pub fn tumbler_paper_command(args: &TumblerPaperArgs) -> Result<(), AnalysisError> {
    println!("wrote {}", write_tumbler_paper_report(args)?.display());
    Ok(())
}

/// Analyses the runs, writes `TUMBLER_PAPER.md` and its two figures into `args.out`; returns the report's path.
pub fn write_tumbler_paper_report(args: &TumblerPaperArgs) -> Result<PathBuf, AnalysisError> {
    let mut runs = Vec::new();
    for d in &args.runs {
        runs.push(analyse_tumbler_run(d)?);
        if let Some(compact) = &args.compact {
            let name = d
                .file_name()
                .ok_or_else(|| AnalysisError::Input(format!("{}: a run directory has a name", d.display())))?;
            write_tumbler_compact(d, &compact.join(name))?;
        }
    }
    runs.sort_by(|a, b| {
        a.froude
            .total_cmp(&b.froude)
            .then(a.eps_n.total_cmp(&b.eps_n))
            .then(a.eps_t.total_cmp(&b.eps_t))
    });
    let command = format!(
        "rubblepile report richardson2011-tumbler {} --out {}",
        args.runs
            .iter()
            .map(|d| d.display().to_string())
            .collect::<Vec<_>>()
            .join(" "),
        args.out.display()
    );
    let fig_dir = args.out.join("figures");
    write_figure(&fig_dir, "tumbler_paper_angle_vs_froude", &angle_chart(&runs))?;
    write_figure(&fig_dir, "tumbler_paper_angle_vs_time", &time_chart(&runs))?;
    let path = args.out.join(TUMBLER_PAPER_FILE);
    std::fs::write(&path, tumbler_paper_markdown(&runs, &command))
        .map_err(|e| AnalysisError::Output(format!("{}: {e}", path.display())))?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_dirs::temp_dir;

    /// A smooth drum (no lining) at the same restitution is labelled apart, so the angle chart never pools it
    /// with lined drums (their angles differ by 28°: NOTES row 20).
    #[test]
    fn smooth_drum_runs_are_not_pooled_with_lined_ones() {
        assert_ne!(drum_label((0.8, 0.8), 0), drum_label((0.8, 0.8), 182));
        assert_eq!(drum_label((0.8, 0.8), 182), drum_label((0.8, 0.8), 568));
        assert!(drum_label((0.8, 0.8), 0).contains("smooth drum"));
    }

    /// The paper's scale: particle radius 0.53 mm, wall at 31.06 mm, so the lining's inner edge is at 30 mm.
    const R_PART: f64 = 0.53e-3;
    const R_WALL: f64 = 0.03106;
    const OMEGA: f64 = 4.0;

    /// A hexagonally packed bed of free particles (spacing 2r) inside the lining, below the line z = −tan(θ) x.
    fn tilted_bed(theta_deg: f64) -> Vec<(f64, f64)> {
        let inner = R_WALL - 3.0 * R_PART;
        let slope = -theta_deg.to_radians().tan();
        let mut c = Vec::new();
        for i in -40..=40 {
            for k in -40..=40 {
                let x = 2.0 * R_PART * i as f64 + if k % 2 == 0 { 0.0 } else { R_PART };
                let z = 2.0 * R_PART * k as f64 * 0.866;
                if x.hypot(z) < inner && z < slope * x {
                    c.push((x, z));
                }
            }
        }
        c
    }

    fn write_run(dir: &std::path::Path, theta_deg: f64) {
        write_run_at(dir, theta_deg, OMEGA);
    }

    /// [`write_run`] with the drum's spin `omega` (rad/s).
    fn write_run_at(dir: &std::path::Path, theta_deg: f64, omega: f64) {
        std::fs::write(
            dir.join("scene.toml"),
            format!(
                "[stepping]\ndt = 5e-4\n[gravity]\nuniform = [0.0, 0.0, -9.81]\n[material]\neps_n = 0.5\neps_t = 0.3\n[[wall]]\nkind = \"cylinder\"\n\
                 radius = {R_WALL:?}\nspin = {omega:?}\n"
            ),
        )
        .unwrap();
        // Stopped at t = 0.4 s: no summary.json; the time series holds per-row collision counts and the wall clock.
        std::fs::write(
            dir.join("timeseries.csv"),
            "t,kinetic,energy_residual,collisions,wall_seconds\n0e0,0,0,0,0.5\n2e-1,1,-3e-3,100,5\n4e-1,1,2e-3,300,12\n",
        )
        .unwrap();
        std::fs::create_dir_all(dir.join("snapshots")).unwrap();
        // Flat at first, tilted in the second half of the run (t ≥ 0.2 s), which is all the angle is taken over.
        for (k, t) in [0.0, 0.1, 0.2, 0.3, 0.4].into_iter().enumerate() {
            let bed = tilted_bed(if t < 0.2 { 0.0 } else { theta_deg });
            let mut s = String::from("t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz,stuck_to\n");
            let _ = writeln!(s, "{t},0,1e-6,{R_PART},0,0,{},0,0,0,0,0,0,0", -(R_WALL - R_PART));
            for (n, (x, z)) in bed.iter().enumerate() {
                let _ = writeln!(s, "{t},{},1e-6,{R_PART},{x},0,{z},0,0,0,0,0,0,-1", n + 1);
            }
            std::fs::write(dir.join(format!("snapshots/{k}.csv")), s).unwrap();
        }
    }

    #[test]
    fn a_stopped_run_of_a_bed_tilted_at_35_degrees_reports_35_degrees_and_its_time_series_totals() {
        let root = temp_dir("tumbler_paper");
        let run_dir = root.join("run");
        std::fs::create_dir_all(&run_dir).unwrap();
        write_run(&run_dir, 35.0);
        let run = analyse_tumbler_run(&run_dir).unwrap();
        assert_eq!(run.status, "interrupted");
        assert_eq!(run.t_reached, 0.4);
        assert_eq!(run.collisions, 400);
        assert!((run.wall_seconds - 12.0).abs() < 1e-12 && (run.events_per_second - 400.0 / 12.0).abs() < 1e-9);
        assert_eq!(run.restitution(), (0.5, 0.3));
        // Three snapshots in the second half, each at 35° to within the column discretisation, with a fit error well
        // under a degree (the packed surface is a staircase about the line).
        assert_eq!(run.angles.len(), 3);
        assert!((run.angle.0 - 35.0).abs() < 2.0, "angle {:?}", run.angle);
        assert_eq!(run.angle_fit_errors.len(), 3);
        // The history holds every snapshot: flat (0°, an exact line, no fit error) before the tilt.
        assert_eq!(run.angle_history.len(), 5);
        assert!(
            run.angle_history[..2]
                .iter()
                .all(|h| h.1.abs() < 1e-9 && h.2.abs() < 1e-9),
            "{:?}",
            run.angle_history
        );
        assert_eq!(
            &run.angle_history[2..].iter().map(|h| (h.0, h.1)).collect::<Vec<_>>(),
            &run.angles
        );
        assert!(
            run.angle_fit_errors.iter().all(|e| *e > 0.0 && *e < 1.0),
            "{:?}",
            run.angle_fit_errors
        );
        // Fr with R = 31.06 − 2 × 0.53 = 30 mm, and R/r = 30 / 0.53.
        assert!((lining_froude(&run) - OMEGA * OMEGA * 0.030 / 9.81).abs() < 1e-12);
        // The step from the scene and, for a stopped run, the largest |energy_residual| of the time series.
        assert_eq!(run.dt, 5e-4);
        assert_eq!(run.energy_error, 3e-3);
        assert!((run.radius_ratio() - 0.030 / R_PART).abs() < 1e-9);
        // The report: one table row with the interrupted status and the angle, and both figures.
        let out = root.join("out");
        let compact = root.join("compact");
        let path = write_tumbler_paper_report(&TumblerPaperArgs {
            runs: vec![run_dir.clone()],
            out: out.clone(),
            compact: Some(compact.clone()),
        })
        .unwrap();
        // The compact copy analyses to the same run (its directory aside), so the report regenerates from it.
        let mut again = analyse_tumbler_run(&compact.join("run")).unwrap();
        assert_eq!(again.dir, compact.join("run"));
        again.dir = run.dir.clone();
        assert_eq!(format!("{again:?}"), format!("{run:?}"));
        assert!(
            std::fs::read_dir(compact.join("run")).unwrap().count() == 2,
            "two CSV files, no snapshots"
        );
        let md = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            md,
            tumbler_paper_markdown(std::slice::from_ref(&run), &md_command(&run_dir, &out))
        );
        let row = md.lines().find(|l| l.contains("| interrupted |")).expect("table row");
        assert!(
            row.contains(&format!("{:.1} ± {:.1}", run.angle.0, run.angle.1)),
            "{row}"
        );
        assert!(
            row.starts_with(&format!("| {:.3} | 0.5 | 0.3 |", lining_froude(&run))),
            "{row}"
        );
        for f in ["tumbler_paper_angle_vs_froude.png", "tumbler_paper_angle_vs_time.png"] {
            assert!(out.join("figures").join(f).is_file(), "{f}");
        }
        std::fs::remove_dir_all(&root).unwrap();
    }

    fn md_command(run: &std::path::Path, out: &std::path::Path) -> String {
        format!(
            "rubblepile report richardson2011-tumbler {} --out {}",
            run.display(),
            out.display()
        )
    }

    #[test]
    fn a_run_without_summary_or_time_series_is_an_input_error_naming_the_file() {
        let root = temp_dir("tumbler_paper_bad");
        let run_dir = root.join("run");
        std::fs::create_dir_all(&run_dir).unwrap();
        write_run(&run_dir, 30.0);
        std::fs::remove_file(run_dir.join("timeseries.csv")).unwrap();
        let e = analyse_tumbler_run(&run_dir).unwrap_err().to_string();
        assert!(e.contains("summary.json"), "{e}");
        std::fs::remove_dir_all(&root).unwrap();
    }

    /// Guards the Fig. 8 comparison against centrifuging runs: at Fr ≥ 1 the paper estimates no slope, so the table
    /// prints none (a line through a bed spread round the lining is not a dynamic angle of repose) while a subcritical
    /// run keeps its angle.
    #[test]
    fn a_centrifuging_run_gets_no_slope_in_the_table() {
        let root = temp_dir("tumbler_paper_centrifuging");
        let (slow, fast) = (root.join("slow"), root.join("fast"));
        for d in [&slow, &fast] {
            std::fs::create_dir_all(d).unwrap();
        }
        write_run(&slow, 30.0);
        // Fr = ω² R / g = 1.2 with R = 30 mm.
        write_run_at(&fast, 30.0, (1.2f64 * 9.81 / 0.030).sqrt());
        let out = root.join("out");
        let path = write_tumbler_paper_report(&TumblerPaperArgs {
            runs: vec![slow, fast],
            out,
            compact: None,
        })
        .unwrap();
        let md = std::fs::read_to_string(&path).unwrap();
        let row = |fr: &str| {
            md.lines()
                .find(|l| l.starts_with(&format!("| {fr} |")))
                .unwrap()
                .to_string()
        };
        assert!(row("1.200").contains("— (Fr ≥ 1: no slope)"), "{}", row("1.200"));
        assert!(
            !row("1.200").contains(" / "),
            "no halves of a slope either: {}",
            row("1.200")
        );
        assert!(!row("0.049").contains("no slope"), "{}", row("0.049"));
        std::fs::remove_dir_all(&root).unwrap();
    }
}
