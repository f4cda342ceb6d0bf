//! Running a campaign: which runs to start, resume or skip, the pool of workers, progress, and the index kept
//! current as runs start and end.

use std::io::IsTerminal;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

use crate::driver::{RunError, RunOptions, resume_run};
use crate::ellipsoid::output::read_bodies_csv;
use crate::impact::run::{ImpactError, ImpactPlan, run_impact};
use crate::io::checkpoint::CHECKPOINT_FILE;
use crate::io::messages::{Channel, emit};

use super::*;

/// How a campaign runs (not what it runs); the default: [`RunOptions::default`], the file's `parallel`, quiet.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CampaignOptions {
    /// Options of every run: the checkpoint cadence and the testing stop (`force` is ignored: a run is
    /// started afresh only as the module docs say); `progress` = the campaign's progress display on stderr
    /// (only when stderr is a terminal). The runs' own progress bars are never shown.
    pub run: RunOptions,
    /// Runs at once, overriding `campaign.parallel`.
    pub parallel: Option<usize>,
    /// Threads of each run's own rayon pool; `None`: the threads of the calling pool shared among the runs at
    /// once, at least one each (see [`threads_per_run`]).
    pub threads_per_run: Option<usize>,
    /// Print one line per finished run on stdout.
    pub verbose: bool,
    /// Run only this shard of the grid ([`Shard`]); its index goes to its own file.
    pub shard: Option<Shard>,
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

/// Whether `dir` holds the run `plan` describes: its `scene.toml` parses to the scene this campaign would write
/// (compared as values: comments and layout aside, as an older build wrote it) and its `initial_bodies.csv` (bit
/// for bit) is the one it would write.
fn same_run(dir: &Path, plan: &ImpactPlan) -> Result<(), String> {
    let scene = std::fs::read_to_string(dir.join("scene.toml")).map_err(|e| format!("scene.toml: {e}"))?;
    if crate::ellipsoid::scene::parse_toml(&scene, "scene.toml").ok().as_ref() != Some(&plan.scene) {
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
    if !completed && !dir.join(CHECKPOINT_FILE).is_file() {
        return (Action::Start, None);
    }
    let action = if completed { Action::Skip } else { Action::Resume };
    let numbers = numbers.filter(|_| completed);
    match same_run(dir, plan) {
        Ok(()) => (action, numbers),
        Err(why) => (conflict(why), numbers),
    }
}

/// The record of every grid point of `campaign` as it starts, from what its run directory holds ([`decide`]:
/// completed runs skipped, directories of another run failed, the rest pending), and the indices of the points to
/// run (to resume or start; only those of `shard` when given), in the grid's order.
pub fn plan_runs(campaign: &Campaign, shard: Option<Shard>) -> (Vec<RunRecord>, Vec<usize>) {
    let runs: Vec<RunRecord> = campaign
        .points
        .iter()
        .map(|p| {
            let (action, numbers) = decide(&campaign.out.join(&p.name), &p.plan);
            let status = match &action {
                Action::Skip => RunStatus::Completed,
                Action::Conflict(why) => RunStatus::Failed(why.clone()),
                Action::Resume | Action::Start => RunStatus::Pending,
            };
            RunRecord {
                name: p.name.clone(),
                action,
                status,
                stopped: false,
                numbers,
            }
        })
        .collect();
    let todo = (0..runs.len())
        .filter(|&i| matches!(runs[i].action, Action::Resume | Action::Start))
        .filter(|&i| shard.is_none_or(|s| s.contains(i)))
        .collect();
    (runs, todo)
}

pub(crate) fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Runs the grid point `point` in its run directory `dir` as `action` says ([`Action::Resume`] from its
/// checkpoint, else afresh; [`decide`] chooses), with `options` but never forced nor with a progress bar: its new
/// status, whether it stopped on request (then pending, to resume), its numbers. A failed run or a panic is a
/// [`RunStatus::Failed`], not an error. Every campaign runner runs its points through this, so a run directory
/// holds the same bytes whichever runner ran it.
pub fn run_point(
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
        // Stopped on request or by its budget: its checkpoint lets the next campaign run resume it.
        Ok(Err(ImpactError::Run(RunError::Stopped { .. } | RunError::Budget { .. }))) => {
            (RunStatus::Pending, true, None)
        }
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

    /// Emits `line` with the bars cleared and redrawn after it, so the line is not drawn over by them.
    fn println(&self, line: &str) {
        self.multi.suspend(|| emit(Channel::Out, line));
    }
}

/// Threads of each run's pool when `parallel` runs go at once and the caller gives none: the calling pool's
/// threads (rayon's current pool; the process's `--threads-per-rank`) shared among the runs, at least one each.
/// Each run has its own pool, so `parallel` runs on one thread each really run at once: with one shared pool of
/// one thread they took turns on it (`analysis/scaling/REPORT.md`, "Campaigns").
pub fn threads_per_run(parallel: usize, given: Option<usize>) -> usize {
    given
        .unwrap_or_else(|| rayon::current_num_threads() / parallel.max(1))
        .max(1)
}

/// Runs `campaign` (see the module docs): creates its directory, decides what to do with each grid point,
/// writes `campaign.csv`, runs what needs running with `parallel` runs at once, rewriting `campaign.csv`
/// whenever a run starts or ends. The campaign directory is locked for as long ([`lock_campaign_dir`]), each run's
/// directory by its run. Failed runs are recorded, not returned (a run directory another process writes is a failed
/// run): the error is only for the campaign directory or `campaign.csv` that cannot be written, or that another
/// process writes ([`CampaignError::Locked`], at once).
pub fn run_campaign(campaign: &Campaign, options: &CampaignOptions) -> Result<CampaignReport, CampaignError> {
    let started = Instant::now();
    let out = &campaign.out;
    std::fs::create_dir_all(out).map_err(|source| CampaignError::Io {
        path: out.clone(),
        source,
    })?;
    let _lock = lock_campaign_dir(out, options.shard)?;
    if let Some(src) = &campaign.source {
        let pointer = out.join(CAMPAIGN_SOURCE);
        let line = format!("{}\n", src.display());
        // Rewritten only when it changes: a resumed campaign leaves its directory's files untouched.
        if std::fs::read_to_string(&pointer).ok().as_deref() != Some(line.as_str()) {
            crate::io::safe_write::write_atomic(&pointer, line)
                .map_err(|source| CampaignError::Io { path: pointer, source })?;
        }
    }
    let index_file = options.shard.map_or(CAMPAIGN_CSV.to_string(), |s| s.index_file());
    let index_file = index_file.as_str();
    let points = &campaign.points;
    let (runs, todo) = plan_runs(campaign, options.shard);
    write_campaign_csv(out, index_file, points, &runs)?;
    let finished_before = (runs.len() - todo.len()) as u64;
    let display = (options.run.progress && std::io::stderr().is_terminal() && !todo.is_empty())
        .then(|| Display::new(runs.len() as u64, finished_before));
    let say = |line: String| {
        if options.verbose {
            match &display {
                Some(d) => d.println(&line),
                None => emit(Channel::Out, &line),
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
    let run_threads = threads_per_run(parallel, options.threads_per_run);

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
                    // The worker's own pool: its runs fork their parallel passes over it alone.
                    let pool = match rayon::ThreadPoolBuilder::new().num_threads(run_threads).build() {
                        Ok(pool) => pool,
                        Err(e) => {
                            lock(&state).1.get_or_insert(CampaignError::Io {
                                path: out.clone(),
                                source: std::io::Error::other(format!(
                                    "cannot build a pool of {run_threads} threads: {e}"
                                )),
                            });
                            return;
                        }
                    };
                    loop {
                        let k = next.fetch_add(1, Ordering::SeqCst);
                        let Some(&i) = todo.get(k) else { break };
                        let point = &points[i];
                        let action = {
                            let mut st = lock(&state);
                            st.0[i].status = RunStatus::Running;
                            if let Err(e) = write_campaign_csv(out, index_file, points, &st.0) {
                                st.1.get_or_insert(e);
                            }
                            st.0[i].action.clone()
                        };
                        if let Some(d) = &display {
                            d.start(i, &point.name);
                        }
                        let (status, stopped, numbers) =
                            pool.install(|| run_point(point, &out.join(&point.name), &action, &options.run));
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
                            if let Err(e) = write_campaign_csv(out, index_file, points, &st.0) {
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
