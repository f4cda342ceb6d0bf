//! `campaign.csv`: one row per grid point with its status and outcome, rewritten atomically.

use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

use crate::driver::RunSummary;
use crate::io::fmt_f64;

use super::*;

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
    pub fn from_summary_text(text: &str) -> Self {
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

    /// What the command line must report as an error, with its exit code: failed runs (1, their causes are in
    /// `index`), runs stopped after a checkpoint on request (3).
    pub fn problem(&self, index: &Path) -> Option<(String, u8)> {
        let stopped = self.runs.iter().filter(|r| r.stopped).count();
        if self.failed() > 0 {
            let (n, all) = (self.failed(), self.runs.len());
            Some((format!("{n} of {all} runs failed (causes in {})", index.display()), 1))
        } else if stopped > 0 {
            Some((
                format!(
                    "{stopped} runs stopped after a checkpoint (--stop-after-checkpoints); run the campaign again to \
                     resume them"
                ),
                3,
            ))
        } else {
            None
        }
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

/// A number for `campaign.csv`: shortest round-trip form, plain between 1e-4 and 1e15, else with an exponent.
pub(crate) fn fmt_num(x: f64) -> String {
    if x == 0.0 || (1e-4..1e15).contains(&x.abs()) {
        format!("{x}")
    } else {
        fmt_f64(x)
    }
}

/// Writes the index `out/file` ([`CAMPAIGN_CSV`] or a shard's [`Shard::index_file`]): [`CAMPAIGN_COLUMNS`] and one
/// column per swept path, one row per grid point of `points` with its record of `runs` (in the same order);
/// atomically and durably, never through a link ([`crate::io::safe_write`]).
pub fn write_campaign_csv(
    out: &Path,
    file: &str,
    points: &[GridPoint],
    runs: &[RunRecord],
) -> Result<(), CampaignError> {
    let path = out.join(file);
    let mut w = csv::Writer::from_writer(Vec::new());
    let to_io = |e: String| CampaignError::Io {
        path: path.clone(),
        source: std::io::Error::other(e),
    };
    // one column per swept path after the fixed ones (none without a sweep)
    let swept = points.first().map_or(&[][..], |p| &p.overrides[..]);
    let header = CAMPAIGN_COLUMNS
        .iter()
        .copied()
        .chain(swept.iter().map(|(path, _)| path.as_str()));
    w.write_record(header).map_err(|e| to_io(e.to_string()))?;
    for (p, r) in points.iter().zip(runs) {
        let n = r.numbers.unwrap_or_default();
        let f = |x: Option<f64>| x.map(fmt_num).unwrap_or_default();
        let u = |x: Option<u64>| x.map(|x| x.to_string()).unwrap_or_default();
        w.write_record(
            [
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
            ]
            .into_iter()
            .chain(p.overrides.iter().map(|(_, v)| v.clone())),
        )
        .map_err(|e| to_io(e.to_string()))?;
    }
    let bytes = w.into_inner().map_err(|e| to_io(e.to_string()))?;
    crate::io::safe_write::write_atomic_durable(&path, bytes).map_err(|source| CampaignError::Io { path, source })
}

/// The last `t` in a (growing) `timeseries.csv`, for the progress display.
pub(crate) fn last_time(path: &Path) -> Option<f64> {
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
