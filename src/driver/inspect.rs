//! Whether a run directory is whole: `rubblepile check DIR` ([`check_run_dir`]), and the snapshots the runner's `resume`
//! makes sure of before it continues a run ([`missing_snapshots`]).
//!
//! A run directory is whole when everything its own record says was written is there: the scene copy; every
//! snapshot the schedule put at or before the time the run reached (for a completed run, all of them; for a failed
//! run, those up to its last time-series row; for a run in progress or interrupted, those up to its checkpoint),
//! each readable by the run's engine and holding its time; and a time series as long as the summary or the
//! checkpoint says. A run still going is read as it stands (nothing is locked: checking never gets in a writer's
//! way), so it is whole as long as what its checkpoint counts is there.
//!
//! Before all that, every file the run's manifest records ([`crate::io::manifest`]) is checked against its size and
//! checksum, and the first damaged one is the first problem named. A run directory written before the manifest is
//! said to have none, and its snapshots and time series are checked row by row instead.

use std::path::{Path, PathBuf};

use super::scene_kind::SceneKind;
use crate::bits::fnv1a_hex;
use crate::ellipsoid::run::EllipsoidEngine;
use crate::engine::{Engine, Sample};
use crate::granular::hard::run::HardEngine;
use crate::granular::soft::run::SoftEngine;
use crate::io::checkpoint::CHECKPOINT_FILE;

/// One line of a [`RunDirReport`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Finding {
    /// Whether it makes the directory not whole.
    pub problem: bool,
    /// What was found (one line).
    pub line: String,
}

/// What [`check_run_dir`] found, one finding per line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RunDirReport {
    /// The run directory.
    pub dir: PathBuf,
    /// Findings in the order checked: what the run is, its status, its time series, its snapshots, then problems.
    pub findings: Vec<Finding>,
}

impl RunDirReport {
    /// The findings that make the directory not whole.
    pub fn problems(&self) -> impl Iterator<Item = &Finding> {
        self.findings.iter().filter(|f| f.problem)
    }

    /// The verdict on `dir` in one line: `Ok("DIR is whole")`, or `Err` naming the first problem and how many
    /// more there are.
    pub fn verdict(&self, dir: &Path) -> Result<String, String> {
        let problems: Vec<&str> = self.problems().map(|f| f.line.as_str()).collect();
        match problems.as_slice() {
            [] => Ok(format!("{} is whole", dir.display())),
            [first, rest @ ..] => Err(format!(
                "{} is not whole: {first}{}",
                dir.display(),
                match rest.len() {
                    0 => String::new(),
                    1 => " (and 1 more problem)".into(),
                    n => format!(" (and {n} more problems)"),
                }
            )),
        }
    }

    fn note(&mut self, line: String) {
        self.findings.push(Finding { problem: false, line });
    }

    fn problem(&mut self, line: String) {
        self.findings.push(Finding { problem: true, line });
    }
}

/// The snapshots among `samples` (those written before some point of a run) that are not files in `dir/snapshots/`:
/// `(k, t)` in order.
pub fn missing_snapshots(dir: &Path, samples: &[Sample]) -> Vec<(usize, f64)> {
    samples
        .iter()
        .filter_map(|s| s.snapshot.map(|k| (k, s.t)))
        .filter(|(k, _)| !snapshot_path(dir, *k).is_file())
        .collect()
}

/// `dir/snapshots/<k>.csv`.
fn snapshot_path(dir: &Path, k: usize) -> PathBuf {
    dir.join("snapshots").join(format!("{k}.csv"))
}

/// One line naming the missing snapshots of `dir` (from [`missing_snapshots`]) that were written by the time
/// described by `by` (e.g. `the checkpoint at t = 8 s`).
pub fn describe_missing(dir: &Path, missing: &[(usize, f64)], by: &str) -> String {
    let snaps = dir.join("snapshots");
    let Some(&(k, t)) = missing.first() else {
        return String::new();
    };
    if !snaps.is_dir() {
        return format!(
            "{}/ is missing ({} snapshot{} written by {by})",
            snaps.display(),
            missing.len(),
            if missing.len() == 1 { "" } else { "s" }
        );
    }
    let first = snapshot_path(dir, k);
    match missing.len() {
        1 => format!(
            "{} is missing (snapshot {k} at t = {t} s, written by {by})",
            first.display()
        ),
        n => format!(
            "{} and {} more snapshots are missing (snapshots {} written by {by})",
            first.display(),
            n - 1,
            missing
                .iter()
                .map(|(k, _)| k.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The parts of `checkpoint.json` that say how far a run got.
struct CheckpointFacts {
    t: f64,
    next_sample: u64,
    rows: u64,
    bytes: u64,
    scene_hash: String,
    scene_base_dir: Option<PathBuf>,
}

fn read_checkpoint_facts(path: &Path) -> Result<CheckpointFacts, String> {
    let text = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| e.to_string())?;
    let int = |k: &str| v.get(k).and_then(|x| x.as_u64()).ok_or(format!("no `{k}`"));
    Ok(CheckpointFacts {
        t: v.get("t_seconds").and_then(|x| x.as_f64()).ok_or("no `t_seconds`")?,
        next_sample: int("next_sample")?,
        rows: int("timeseries_rows")?,
        bytes: int("timeseries_bytes")?,
        scene_hash: v
            .get("scene_hash")
            .and_then(|x| x.as_str())
            .unwrap_or_default()
            .to_string(),
        scene_base_dir: v.get("scene_base_dir").and_then(|x| x.as_str()).map(PathBuf::from),
    })
}

/// Checks the files `dir`'s manifest records ([`crate::io::manifest::verify_entry`]), as
/// [`crate::io::manifest::verify_all`] but leaving a missing snapshot or time series to the checks below, which say
/// what the schedule expected of them.
fn verify_manifest(dir: &Path) -> Result<Option<usize>, String> {
    let Some(m) = crate::io::manifest::read(dir)? else {
        return Ok(None);
    };
    let mut verified = 0;
    for e in &m.entries {
        // The time series cut short is told below too, against what the checkpoint or summary counts.
        let short = std::fs::metadata(dir.join(&e.path)).map_or(true, |m| m.len() < e.bytes);
        let told_below = e.path.starts_with("snapshots/") && !dir.join(&e.path).exists();
        if told_below || (e.path == "timeseries.csv" && short) {
            continue;
        }
        crate::io::manifest::verify_entry(dir, e)?;
        verified += 1;
    }
    Ok(Some(verified))
}

/// Checks whether the run directory `dir` is whole (module docs); never writes or locks anything.
pub fn check_run_dir(dir: &Path) -> RunDirReport {
    let mut report = RunDirReport {
        dir: dir.to_path_buf(),
        findings: Vec::new(),
    };
    let scene_path = dir.join("scene.toml");
    let Ok(text) = std::fs::read_to_string(&scene_path) else {
        report.problem(format!(
            "{} is missing: not a run directory, or its scene copy was lost",
            scene_path.display()
        ));
        return report;
    };
    let manifest = verify_manifest(dir);
    match &manifest {
        Ok(Some(n)) => report.note(format!(
            "manifest: the {n} files it records that are there match their sizes and BLAKE3 checksums"
        )),
        Ok(None) => report.note(format!(
            "no manifest ({} is missing: a run directory written before rubblepile recorded checksums); its \
             snapshots and time series are checked row by row",
            dir.join(crate::io::manifest::MANIFEST_FILE).display()
        )),
        Err(e) => report.problem(e.clone()),
    }
    let ckpt_path = dir.join(CHECKPOINT_FILE);
    let ckpt = match ckpt_path.is_file().then(|| read_checkpoint_facts(&ckpt_path)) {
        None => None,
        Some(Ok(c)) => Some(c),
        Some(Err(e)) => {
            report.problem(format!("{}: corrupt checkpoint: {e}", ckpt_path.display()));
            None
        }
    };
    // Relative input files resolve as `resume` resolves them (the checkpoint's record), else from the run directory
    // (where `impact` and `flyby` put theirs) or the current one.
    let mut bases: Vec<PathBuf> = ckpt.iter().filter_map(|c| c.scene_base_dir.clone()).collect();
    bases.extend([dir.to_path_buf(), PathBuf::from(".")]);
    // Without a manifest, the rows are what there is to check.
    let rows = matches!(manifest, Ok(None));
    match SceneKind::of_text(&text) {
        SceneKind::Ellipsoids => check_with::<EllipsoidEngine>(&mut report, &text, &bases, ckpt.as_ref(), rows),
        SceneKind::SoftSpheres => check_with::<SoftEngine>(&mut report, &text, &bases, ckpt.as_ref(), rows),
        SceneKind::HardSpheres => check_with::<HardEngine>(&mut report, &text, &bases, ckpt.as_ref(), rows),
    }
    report
}

/// How far a run got by its own record, and what that promises.
enum Reached {
    /// `summary.json` says completed: every sample.
    Completed,
    /// `summary.json` says failed: the samples of the time series' rows.
    Failed,
    /// A checkpoint and no final summary: the samples before it.
    Checkpoint,
    /// Neither: what the time series holds (the last row's snapshot may be being written).
    Unknown,
}

fn check_with<E: Engine>(
    report: &mut RunDirReport,
    text: &str,
    bases: &[PathBuf],
    ckpt: Option<&CheckpointFacts>,
    rows_too: bool,
) {
    let dir = report.dir.clone();
    let name = dir.join("scene.toml").display().to_string();
    // The first base's error is the one to name: the others are guesses.
    let mut built = Err(String::new());
    for (i, base) in bases.iter().enumerate() {
        match E::from_scene_text(text, &name, Some(base)) {
            Ok(e) => {
                built = Ok(e);
                break;
            }
            Err(e) if i == 0 => built = Err(e.to_string()),
            Err(_) => {}
        }
    }
    report.note(format!("{}: a run of kind {:?} (scene.toml)", dir.display(), E::KIND));

    // Status, from summary.json and checkpoint.json.
    let summary_path = dir.join("summary.json");
    let summary_text = std::fs::read_to_string(&summary_path).ok();
    let summary: Option<serde_json::Value> = summary_text.as_deref().and_then(|t| serde_json::from_str(t).ok());
    if summary_text.is_some() && summary.is_none() {
        report.problem(format!("{}: not JSON (damaged?)", summary_path.display()));
    }
    let status = summary
        .as_ref()
        .and_then(|v| v.get("status")?.as_str().map(str::to_string));
    let summary_t = summary
        .as_ref()
        .and_then(|v| v.get("final_time").or(v.get("t_reached"))?.as_f64());
    let at = |t: Option<f64>| t.map_or(String::new(), |t| format!(" at t = {t} s"));
    let reached = match (status.as_deref(), ckpt) {
        (Some("completed"), _) => {
            report.note(format!("status: completed{}", at(summary_t)));
            Reached::Completed
        }
        (Some(s), _) if s.starts_with("failed") => {
            report.note(format!("status: {s}{}", at(summary_t)));
            Reached::Failed
        }
        // A summary that says neither: named as it is, not taken for a missing one.
        (Some(s), _) => {
            report.problem(format!(
                "{}: status {s:?} is none rubblepile writes (\"completed\" or \"failed: …\")",
                summary_path.display()
            ));
            Reached::Unknown
        }
        (_, Some(c)) => {
            report.note(format!(
                "status: in progress (or interrupted), checkpoint at t = {} s; `rubblepile resume {}` continues it",
                c.t,
                dir.display()
            ));
            if fnv1a_hex(text.as_bytes()) != c.scene_hash {
                report.problem(format!(
                    "{}: changed since the checkpoint was written (resume refuses it)",
                    dir.join("scene.toml").display()
                ));
            }
            Reached::Checkpoint
        }
        (_, None) => {
            report.problem(
                "status: no summary.json and no checkpoint.json: the run is still going and has no checkpoint yet, or \
                 it ended before its first one (then it cannot be resumed: run it again)"
                    .into(),
            );
            Reached::Unknown
        }
    };

    // The time series (when it is missing, the snapshots are still checked, as far as the summary says).
    let ts_path = dir.join("timeseries.csv");
    let ts = std::fs::read(&ts_path).ok();
    let rows = ts.as_ref().map(|b| {
        b.split(|&c| c == b'\n')
            .filter(|l| !l.is_empty())
            .count()
            .saturating_sub(1) as u64
    });
    let summary_rows = summary.as_ref().and_then(|v| v.get("samples")?.as_u64());
    match (rows, ckpt, &reached) {
        (None, ..) => report.problem(format!("{} is missing", ts_path.display())),
        (Some(rows), Some(c), Reached::Checkpoint) => {
            report.note(format!(
                "timeseries.csv: {rows} rows, {} of them by the checkpoint",
                c.rows
            ));
            let bytes = ts.as_ref().map_or(0, |b| b.len() as u64);
            if rows < c.rows || bytes < c.bytes {
                report.problem(format!(
                    "{}: {rows} rows ({bytes} bytes), fewer than the {} rows ({} bytes) written before the checkpoint",
                    ts_path.display(),
                    c.rows,
                    c.bytes
                ));
            }
        }
        (Some(rows), ..) => {
            report.note(format!("timeseries.csv: {rows} rows"));
            if rows_too && let Err(e) = crate::io::manifest::check_rows(&ts_path, false) {
                report.problem(e);
            }
            if let (Some(n), Reached::Completed | Reached::Failed) = (summary_rows, &reached)
                && n != rows
            {
                report.problem(format!(
                    "{}: {rows} rows, but summary.json counts {n} samples",
                    ts_path.display()
                ));
            }
        }
    }

    // The snapshots the schedule promises by then.
    let engine = match built {
        Ok(e) => e,
        Err(e) => {
            report.note(format!(
                "snapshots: not checked against the schedule: the scene cannot be loaded here ({e})"
            ));
            return;
        }
    };
    let samples = engine.samples();
    let total = samples.len() as u64;
    let rows = rows.or(summary_rows).unwrap_or(0);
    let (done, by) = match (&reached, ckpt) {
        (Reached::Completed, _) => {
            if rows != total {
                report.problem(format!(
                    "{}: {rows} rows, but the completed run sampled {total} times",
                    ts_path.display()
                ));
            }
            (total, "the end of the run".to_string())
        }
        (Reached::Checkpoint, Some(c)) => (c.next_sample.min(total), format!("the checkpoint at t = {} s", c.t)),
        (Reached::Failed, _) => (rows.min(total), "the failure".to_string()),
        // The last row's snapshot may be being written right now.
        _ => (rows.saturating_sub(1).min(total), String::new()),
    };
    let by = match (by.is_empty(), done.checked_sub(1)) {
        (true, Some(i)) => format!("t = {} s", samples[i as usize].t),
        (true, None) => "t = 0 s".into(),
        (false, _) => by,
    };
    let due = &samples[..done as usize];
    let missing = missing_snapshots(&dir, due);
    let promised = due.iter().filter(|s| s.snapshot.is_some()).count();
    let mut unreadable = 0;
    for s in due {
        let Some(k) = s.snapshot else { continue };
        let p = snapshot_path(&dir, k);
        if !p.is_file() {
            continue;
        }
        if rows_too && let Err(e) = crate::io::manifest::check_rows(&p, true) {
            unreadable += 1;
            report.problem(e);
            continue;
        }
        match engine.view_of_snapshot(&p) {
            Err(e) => {
                unreadable += 1;
                report.problem(format!("{} is unreadable: {e}", p.display()));
            }
            Ok(v) if (v.t - s.t).abs() > 1e-9 * s.t.abs().max(1.0) => {
                unreadable += 1;
                report.problem(format!(
                    "{} holds t = {} s; the schedule puts snapshot {k} at t = {} s",
                    p.display(),
                    v.t,
                    s.t
                ));
            }
            Ok(_) => {}
        }
    }
    report.note(format!(
        "snapshots: {} of the {promised} written by {by} present and readable",
        promised - missing.len() - unreadable
    ));
    if !missing.is_empty() {
        report.problem(describe_missing(&dir, &missing, &by));
    }
}
