//! The search for the third critical spin limit T_c,3 (Zhang17 §3.3.3, §4.2), behind `rubblepile spinup critical`.
//!
//! For T_final = from, from + step, … (hours) a hold run `DIR/T<X>/` spins the pile up to T_final and holds it
//! there; each hold is judged by the creep criteria ([`crate::analysis::critical`], [`crate::analysis::creep`]) and
//! T_c,3 under a criterion is its first stable T_final, φ the largest θ_max of that hold. With `--branch` the holds
//! share one run of the base scene's path (`DIR/base`) and branch off its checkpoints where the path passes each
//! T_final ([`crate::driver::branch`]; Zhang17 §4.3 finds T_c,3 independent of the spin-up rate), so each costs only
//! its hold, and `--parallel N` runs N holds at once. Results go to `critical.json` and `critical.csv`.

use std::path::{Path, PathBuf};

use crate::analysis::creep::{CreepCriterion, CreepCriterionKind};
use crate::analysis::critical::*;
use crate::analysis::spinup_diagnostics::read_spinup_csv;
use crate::driver::RunOptions;
use crate::granular::soft::scene::SoftSceneFile;
use crate::impact::campaign::Shard;
use crate::io::messages::{Channel, emit};
use crate::io::scene_file::{parse_toml_as, scene_text};

/// The options of a T_c,3 search (those of `rubblepile spinup critical`).
#[derive(Debug, Clone, PartialEq)]
pub struct CriticalOptions {
    /// Soft-sphere scene with a `[spinup]` table whose run lasts past `t_final` (the hold).
    pub scene: PathBuf,
    /// First T_final (hours).
    pub from: f64,
    /// Last T_final (hours).
    pub to: f64,
    /// Step of T_final (hours).
    pub step: f64,
    /// Directory of the hold runs and `critical.json`.
    pub out: PathBuf,
    /// Overwrite an earlier `critical.json` in `out` (completed runs are still reused).
    pub force: bool,
    /// Branch the hold runs off one run of the scene's path (`out/base`) instead of running each from t = 0.
    pub branch: bool,
    /// The criterion whose T_c,3 and φ are `critical.json`'s top-level values (all are always judged).
    pub criterion: CreepCriterionKind,
    /// Largest fall of the coordination number (contacts per particle) over the second half of a hold that the
    /// paper-tolerance criterion lets pass; default [`crate::analysis::creep::PAPER_COORDINATION_TOLERANCE`].
    pub coordination_tolerance: Option<f64>,
    /// Standard errors a weakening rate must exceed for the paper's criterion; default
    /// [`crate::analysis::creep::DEFAULT_SIGNIFICANCE`].
    pub significance: Option<f64>,
    /// Length of each hold (s) with `branch`; default: the scene's `t_end − t_final`.
    pub hold: Option<f64>,
    /// Judge only the first this many seconds of each hold (the hold-length study: one long hold read at several
    /// lengths); default: the whole hold.
    pub judge_window: Option<f64>,
    /// Run every hold of the grid, also after every criterion has a stable hold (whether the verdicts stay stable
    /// at slower spins); default: stop there.
    pub all_holds: bool,
    /// Holds run at once (each on its own rayon pool); 1: one after another.
    pub parallel: usize,
    /// Threads of each hold's pool; default: the calling pool's threads shared among the holds at once.
    pub threads_per_hold: Option<usize>,
    /// Run only the holds of this shard of the grid (for a scheduler's job array), then stop without judging;
    /// a run without `shard` afterwards judges them all (finished holds are reused).
    pub shard: Option<Shard>,
    /// Run a hold whose forcing was released to its end; default: stop it at the next release check
    /// ([`RELEASE_CHECK_S`]), its verdict (not stable) being fixed.
    pub finish_released: bool,
    /// Write the base run and every hold's branch (or scene) and stop: the first job of a job array whose shards
    /// then run the holds (shards started together would otherwise all run the base).
    pub prepare_only: bool,
}

impl CriticalOptions {
    /// A search over `from..=to` hours by `step` into `out`, with the defaults of `rubblepile spinup critical`.
    pub fn new(scene: PathBuf, from: f64, to: f64, step: f64, out: PathBuf) -> Self {
        CriticalOptions {
            scene,
            from,
            to,
            step,
            out,
            force: false,
            branch: false,
            criterion: CreepCriterionKind::Paper,
            coordination_tolerance: None,
            significance: None,
            hold: None,
            judge_window: None,
            all_holds: false,
            parallel: 1,
            threads_per_hold: None,
            shard: None,
            finish_released: false,
            prepare_only: false,
        }
    }
}

/// Simulated seconds between the checks of a running hold for a released forcing (each check is a checkpoint):
/// a released hold stops at most this long after its release unless `finish_released` is asked for.
pub const RELEASE_CHECK_S: f64 = 2000.0;

/// Runs the T_c,3 search (Zhang17 §3.3.3) and writes `critical.json` and `critical.csv` in `args.out`.
pub fn critical(args: &CriticalOptions) -> Result<(), SearchError> {
    let say = |line: String| emit(Channel::Out, &line);
    let ok = |x: f64| x.is_finite() && x > 0.0;
    if !ok(args.from) || !ok(args.to) || args.to < args.from {
        return Err(SearchError::usage(format!(
            "--from-h and --to-h must be periods in hours with 0 < from <= to, got {} and {}",
            args.from, args.to
        )));
    }
    if !ok(args.step) {
        return Err(SearchError::usage(format!(
            "--step-h must be > 0 hours, got {}",
            args.step
        )));
    }
    if args.parallel == 0 || args.threads_per_hold == Some(0) {
        return Err(SearchError::usage(
            "--parallel and --threads-per-hold must be at least 1",
        ));
    }
    if let Some(w) = args.judge_window
        && !ok(w)
    {
        return Err(SearchError::usage(format!("--judge-window-s must be > 0 s, got {w}")));
    }
    // without --branch every hold runs the scene from t = 0 to its own t_end, so a hold length has no meaning
    if let Some(hold) = args.hold
        && !args.branch
    {
        return Err(SearchError::usage(format!(
            "--hold-s {hold} needs --branch (without it each hold runs the scene from t = 0 to its t_end: set the \
             hold's length there)"
        )));
    }
    let json = args.out.join("critical.json");
    if json.exists() && !args.force && args.shard.is_none() && !args.prepare_only {
        return Err(SearchError::usage(format!(
            "{} exists (use --force to overwrite it)",
            json.display()
        )));
    }
    let text = std::fs::read_to_string(&args.scene)
        .map_err(|e| SearchError::usage(format!("{}: {e}", args.scene.display())))?;
    let base = crate::granular::soft::scene::load_soft_scene(&args.scene).map_err(SearchError::usage)?;
    let Some(settings) = base.spinup else {
        return Err(SearchError::usage(format!(
            "{}: spinup: missing (need a [spinup] table)",
            args.scene.display()
        )));
    };
    if base.t_end <= settings.path.t_final && !(args.branch && args.hold.is_some()) {
        return Err(SearchError::usage(format!(
            "{}: scene.t_end must exceed spinup.t_final = {} s to leave a hold, got {}",
            args.scene.display(),
            settings.path.t_final,
            base.t_end
        )));
    }
    // the scene as a value, which each hold's scene changes and is written from
    let mut file: SoftSceneFile =
        parse_toml_as(&text, &args.scene.display().to_string()).map_err(|e| SearchError::usage(e.to_string()))?;
    // a particles_file is resolved against the base scene's directory
    let scene_dir = args.scene.parent().map(Path::to_path_buf).unwrap_or_default();
    if let Some(f) = &file.scene.particles_file {
        let abs = std::path::absolute(scene_dir.join(f)).map_err(|e| SearchError::usage(e.to_string()))?;
        file.scene.particles_file = Some(abs.display().to_string());
    }
    std::fs::create_dir_all(&args.out).map_err(|e| SearchError::usage(format!("{}: {e}", args.out.display())))?;
    let criteria = criteria(args.significance, args.coordination_tolerance)?;
    let n = ((args.to - args.from) / args.step + 1e-9).floor() as usize;
    let grid: Vec<f64> = (0..=n)
        .map(|k| ((args.from + k as f64 * args.step) * 1e4).round() / 1e4)
        .collect();
    for &tf in &grid {
        if tf * 3600.0 > settings.path.period_inter + 1e-9 {
            return Err(SearchError::usage(format!(
                "T_final = {tf} h is above the scene's T_inter = {} h",
                settings.path.period_inter / 3600.0
            )));
        }
    }
    if args.shard.is_some() && args.branch {
        // shards started together must not all run the base: it is the job of --prepare-only
        if let Some(tf) = grid.iter().find(|tf| !written(&args.out.join(format!("T{tf:.2}")))) {
            return Err(SearchError::usage(format!(
                "--shard: the branch of T_final = {tf:.2} h is not in {}; run the same command with --prepare-only \
                 (instead of --shard) first",
                args.out.display()
            )));
        }
    }
    let branches = if args.branch {
        Some(prepare_branches(args, &file, &base, &settings.path, &grid)?)
    } else {
        None
    };
    // every hold's scene exists before any runs, so that holds are independent jobs
    let mut jobs = Vec::with_capacity(grid.len());
    for (k, &tf) in grid.iter().enumerate() {
        let dir = args.out.join(format!("T{tf:.2}"));
        let scene = match branches {
            Some(_) => None,
            None => {
                let mut hold = file.clone();
                if let Some(spinup) = hold.spinup.as_mut() {
                    spinup.period_final_h = tf;
                }
                let path = args.out.join(format!("T{tf:.2}.toml"));
                crate::io::safe_write::write_atomic(&path, scene_text(&[], &hold))
                    .map_err(|e| SearchError::failed(format!("{}: {e}", path.display())))?;
                Some(crate::granular::soft::scene::load_soft_scene(&path).map_err(SearchError::usage)?)
            }
        };
        let t_final = branches.as_ref().map_or(settings.path.t_final, |b| b[k]);
        jobs.push(HoldJob {
            t_final_hours: tf,
            t_final,
            dir,
            scene,
        });
    }
    let judge = |job: &HoldJob| -> Result<HoldVerdict, SearchError> {
        let samples = read_spinup_csv(&job.dir.join("spinup.csv")).map_err(SearchError::failed)?;
        Ok(judge_hold(
            &samples,
            job.t_final,
            args.judge_window,
            &criteria,
            args.criterion,
            job.t_final_hours,
            job.dir.clone(),
        ))
    };
    if args.prepare_only {
        say(format!(
            "spinup critical: {} holds prepared in {}; run them with --shard I/N or without it",
            jobs.len(),
            args.out.display()
        ));
        return Ok(());
    }
    if let Some(shard) = args.shard {
        let mine: Vec<&HoldJob> = jobs
            .iter()
            .enumerate()
            .filter(|(k, _)| shard.contains(*k))
            .map(|(_, j)| j)
            .collect();
        run_holds(&mine, args, &|_| false)?;
        say(format!(
            "spinup critical: shard {}/{} ran {} of {} holds; run the search again without --shard to judge them all",
            shard.index,
            shard.count,
            mine.len(),
            jobs.len()
        ));
        return Ok(());
    }
    let all: Vec<&HoldJob> = jobs.iter().collect();
    // the holds run in grid order, `parallel` at once; none is started once the holds already judged (a
    // contiguous prefix of the grid) are enough for the search to stop, as a search one hold at a time would
    let judged = std::sync::Mutex::new(Vec::<Option<HoldVerdict>>::new());
    let enough = |k: usize| -> bool {
        let mut j = judged.lock().expect("no panic holds the lock");
        if j.len() < jobs.len() {
            j.resize(jobs.len(), None);
        }
        if j[k].is_none()
            && let Ok(v) = judge(&jobs[k])
        {
            j[k] = Some(v);
        }
        let prefix: Vec<HoldVerdict> = j.iter().map_while(|v| v.clone()).collect();
        search_stops(&prefix, args.all_holds)
    };
    run_holds(&all, args, &enough)?;
    let mut runs = Vec::new();
    for job in &jobs {
        if !hold_finished(&job.dir, args.finish_released) {
            break;
        }
        runs.push(judge(job)?);
    }
    runs.truncate(sequential_stop(&runs, args.all_holds));
    for r in &runs {
        say(verdict_line(r));
    }
    let result = |criterion: CreepCriterion| {
        let (t_c3_hours, friction_angle_deg) = critical_from_verdicts(&runs, criterion.kind);
        CriterionResult {
            criterion,
            t_c3_hours,
            friction_angle_deg,
            set_aside_hours: set_aside(&runs, criterion.kind),
        }
    };
    let (paper, paper_tolerance, ours) = (
        result(criteria.paper),
        result(criteria.paper_tolerance),
        result(criteria.ours),
    );
    let selected = match args.criterion {
        CreepCriterionKind::Paper => paper.clone(),
        CreepCriterionKind::PaperTolerance => paper_tolerance.clone(),
        CreepCriterionKind::Ours => ours.clone(),
    };
    let (t_c3_hours, friction_angle_deg) = (selected.t_c3_hours, selected.friction_angle_deg);
    let csv = args.out.join("critical.csv");
    crate::io::safe_write::write_atomic(&csv, critical_csv(&runs))
        .map_err(|e| SearchError::failed(format!("{}: {e}", csv.display())))?;
    let out = CriticalSearch {
        criterion: selected.criterion,
        judge_window_s: args.judge_window,
        runs,
        t_c3_hours,
        friction_angle_deg,
        paper,
        paper_tolerance,
        ours,
    };
    crate::io::safe_write::write_atomic(&json, serde_json::to_string_pretty(&out).expect("serialises") + "\n")
        .map_err(|e| SearchError::failed(format!("{}: {e}", json.display())))?;
    for r in [&out.paper, &out.paper_tolerance, &out.ours] {
        if let (Some(first), Some(last)) = (r.set_aside_hours.first(), r.set_aside_hours.last()) {
            say(format!(
                "{} criterion: stable holds at {:?} h lie below creeping ones and are set aside (the verdict is not \
                 monotone there: refine with a finer --step-h from {first:.2} h to the next creeping hold above {last:.2} h)",
                r.criterion.kind.name(),
                r.set_aside_hours
            ));
        }
        let verdict = match (r.t_c3_hours, r.friction_angle_deg) {
            (Some(t), Some(p)) => format!("T_c3 = {t:.2} h, phi = {p:.1} deg"),
            _ => format!(
                "no stable T_final up to {} h{}",
                args.to,
                undecided_note(&out.runs, r.criterion.kind)
            ),
        };
        say(format!("{} criterion: {verdict}", r.criterion.kind.name()));
    }
    say(format!(
        "selected ({}): {} ({})",
        args.criterion.name(),
        t_c3_hours.map_or("no T_c3".to_string(), |t| format!("T_c3 = {t:.2} h")),
        json.display()
    ));
    Ok(())
}

/// One hold of a search: its period, the time its hold starts, its run directory, and its scene when it runs from
/// t = 0 (`None`: a branch already written in `dir`).
struct HoldJob {
    t_final_hours: f64,
    t_final: f64,
    dir: PathBuf,
    scene: Option<crate::granular::soft::scene::SoftScene>,
}

/// Whether the hold (or base) run in `dir` was started or branched there: it holds a checkpoint or a summary.
fn written(dir: &Path) -> bool {
    dir.join("checkpoint.json").is_file() || dir.join("summary.json").is_file()
}

/// Whether the hold in `dir` needs no more running: completed, or its forcing released (its `spinup.csv` says so)
/// unless `finish_released`.
fn hold_finished(dir: &Path, finish_released: bool) -> bool {
    let completed = std::fs::read_to_string(dir.join("summary.json")).is_ok_and(|s| s.contains("\"completed\""));
    let released = || read_spinup_csv(&dir.join("spinup.csv")).is_ok_and(|s| s.iter().any(|x| !x.forcing));
    completed || (!finish_released && released())
}

/// Runs one hold to its end, in legs of [`RELEASE_CHECK_S`] simulated seconds each ending in a checkpoint, and
/// stops after the leg in which its forcing was released unless `finish_released`. A hold already finished is
/// left alone; one stopped midway continues from its checkpoint (bit for bit, [`crate::driver`]).
fn run_hold(job: &HoldJob, finish_released: bool) -> Result<(), SearchError> {
    let failed = |e: crate::driver::RunError<crate::granular::soft::run::SoftSummary>| {
        SearchError::failed(format!("{}: {e}", job.dir.display()))
    };
    loop {
        if hold_finished(&job.dir, finish_released) {
            return Ok(());
        }
        let options = RunOptions {
            force: true,
            progress: false,
            checkpoint_every_sim: Some(RELEASE_CHECK_S),
            stop_after_checkpoints: Some(1),
            ..RunOptions::default()
        };
        let result = match (&job.scene, job.dir.join("checkpoint.json").is_file()) {
            (Some(scene), false) => crate::driver::run_soft(scene, &job.dir, &options),
            _ => crate::driver::resume_soft(&job.dir, &options),
        };
        match result {
            Ok(_) | Err(crate::driver::RunError::Stopped { .. }) => {}
            Err(e) => return Err(failed(e)),
        }
    }
}

/// Runs `jobs` (in order), `args.parallel` at once, each on a rayon pool of its own threads (shared out as a
/// campaign's, [`crate::impact::campaign::threads_per_run`]);
/// `enough(k)` is asked after hold k finishes, and once it says so no further hold is started.
fn run_holds(
    jobs: &[&HoldJob],
    args: &CriticalOptions,
    enough: &(dyn Fn(usize) -> bool + Sync),
) -> Result<(), SearchError> {
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    let next = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let first_error = std::sync::Mutex::new(None);
    let threads = crate::impact::campaign::threads_per_run(args.parallel, args.threads_per_hold);
    let worker = || {
        let pool = match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
            Ok(p) => p,
            Err(e) => {
                *first_error.lock().expect("no panic holds the lock") = Some(SearchError::failed(e.to_string()));
                stop.store(true, Ordering::SeqCst);
                return;
            }
        };
        loop {
            if stop.load(Ordering::SeqCst) {
                return;
            }
            let k = next.fetch_add(1, Ordering::SeqCst);
            let Some(job) = jobs.get(k) else { return };
            if !hold_finished(&job.dir, args.finish_released) {
                emit(
                    Channel::Progress,
                    &format!(
                        "spinup critical: running T_final = {} h into {} ({threads} thread(s))",
                        job.t_final_hours,
                        job.dir.display()
                    ),
                );
            }
            match pool.install(|| run_hold(job, args.finish_released)) {
                Ok(()) => {
                    if enough(k) {
                        stop.store(true, Ordering::SeqCst);
                    }
                }
                Err(e) => {
                    first_error.lock().expect("no panic holds the lock").get_or_insert(e);
                    stop.store(true, Ordering::SeqCst);
                }
            }
        }
    };
    std::thread::scope(|s| {
        for _ in 0..args.parallel.min(jobs.len()).max(1) {
            s.spawn(worker);
        }
    });
    match first_error.into_inner().expect("no panic holds the lock") {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// Checkpointed legs the base run of `--branch` is cut into over its span (a stopped search loses one at most).
const BASE_LEGS: u64 = 8;

/// The output-sample steps at which the base run stops and checkpoints on its way from step `from` to `to` (an
/// output sample): legs of at most `leg_steps` steps where the samples allow (a leg shorter than the sample spacing
/// ends at the next sample), the last one at `to`; empty when `from >= to`.
fn base_legs(samples: &[u64], from: u64, to: u64, leg_steps: u64) -> Vec<u64> {
    let mut legs = Vec::new();
    let mut at = from;
    while at < to {
        let reach = at.saturating_add(leg_steps.max(1)).min(to);
        let next = samples
            .iter()
            .copied()
            .filter(|&s| s > at && s <= reach)
            .max()
            .or_else(|| samples.iter().copied().filter(|&s| s > at && s <= to).min())
            .unwrap_or(to);
        legs.push(next);
        at = next;
    }
    legs
}

/// `--branch`: runs the scene's path once in `OUT/base`, stopping at the output sample at or before each hold's
/// start `t_X` (the time the path passes X = T_final, latest first), and writes the hold run `OUT/T<X>` there as
/// a branch ([`crate::granular::soft::branch`]) whose scene follows the same path to X at `t_X` and holds it for
/// the hold length. Branches already written are kept. Returns `t_X` (s) per grid entry.
fn prepare_branches(
    args: &CriticalOptions,
    file: &SoftSceneFile,
    base: &crate::granular::soft::scene::SoftScene,
    path: &crate::granular::soft::spinup::SpinupPath,
    grid: &[f64],
) -> Result<Vec<f64>, SearchError> {
    use crate::driver::branch::{branch_soft, checkpoint_time};
    use crate::driver::progress::fmt_time;
    use crate::driver::{resume_soft, run_soft};
    use crate::granular::soft::run::sample_steps;
    if path.rests > 0 {
        return Err(SearchError::usage(format!(
            "{}: spinup.rests = {}: --branch needs a path without rests (a shorter path with rests is not a prefix)",
            args.scene.display(),
            path.rests
        )));
    }
    let hold = args.hold.unwrap_or(base.t_end - path.t_final);
    if !(hold.is_finite() && hold > 0.0) {
        return Err(SearchError::usage(format!("--hold-s must be > 0 s, got {hold}")));
    }
    let mut starts = Vec::with_capacity(grid.len());
    for &tf in grid {
        starts.push(path_time_at_period(path, tf).ok_or_else(|| {
            SearchError::usage(format!(
                "T_final = {tf} h is outside the scene's path from T_inter = {} h to T_final = {} h",
                path.period_inter / 3600.0,
                path.period_final / 3600.0
            ))
        })?);
    }
    let dt = base.dt;
    let every = base.every_steps as f64 * dt;
    // the scene's snapshot times, from its list or its cadence: the base and hold scenes list theirs (issue 57)
    let times: Vec<f64> = match (&file.output.times, file.output.snapshot_every) {
        (Some(times), _) => times.clone(),
        (None, Some(every)) => crate::io::output_times::cadence_times(file.scene.t_end, every),
        (None, None) => vec![0.0],
    };
    // the base scene: the path run to just past the earliest hold's start
    let t_base_end = starts.iter().cloned().fold(0.0, f64::max) + 2.0 * every;
    let keep = |limit: f64| -> Vec<f64> { times.iter().copied().filter(|&t| t <= limit + 1e-9).collect() };
    let mut base_file = file.clone();
    base_file.scene.t_end = t_base_end;
    base_file.output.times = Some(keep(t_base_end));
    base_file.output.snapshot_every = None;
    let base_text = scene_text(&[], &base_file);
    let parent = args
        .scene
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let scene_dir =
        std::path::absolute(parent).map_err(|e| SearchError::usage(format!("{}: {e}", parent.display())))?;
    let base_scene = crate::granular::soft::scene::parse_soft_scene(&base_text, "base", Some(&scene_dir))
        .map_err(SearchError::usage)?;
    let plan = sample_steps(&base_scene);
    let base_dir = args.out.join("base");
    // a base run from an earlier search over a shorter span cannot be extended (its scene is fixed); its scene is
    // compared as a value, so that one an older build wrote in another layout (defaults left out) is recognised
    if let Ok(text) = std::fs::read_to_string(base_dir.join("scene.toml"))
        && parse_toml_as::<SoftSceneFile>(&text, "scene.toml").ok().as_ref() != Some(&base_file)
        && grid.iter().any(|tf| !written(&args.out.join(format!("T{tf:.2}"))))
    {
        return Err(SearchError::usage(format!(
            "{}: the base run was made for another range of T_final; remove that directory to start it again \
             (the hold runs already branched are kept)",
            base_dir.display()
        )));
    }
    let failed =
        |e: crate::driver::RunError<crate::granular::soft::run::SoftSummary>| SearchError::failed(e.to_string());
    let sample_list: Vec<u64> = plan.iter().map(|p| p.0).collect();
    let leg_steps = sample_list.last().copied().unwrap_or(0).div_ceil(BASE_LEGS).max(1);
    // latest hold first: the base run only moves forward
    let mut order: Vec<usize> = (0..grid.len()).collect();
    order.sort_by(|&a, &b| starts[a].total_cmp(&starts[b]));
    for k in order {
        let tf = grid[k];
        let dir = args.out.join(format!("T{tf:.2}"));
        if written(&dir) {
            continue;
        }
        let s_x = (starts[k] / dt + 1e-9).floor() as u64;
        let s_ck = plan
            .iter()
            .map(|p| p.0)
            .filter(|&s| s <= s_x && s > 0)
            .max()
            .unwrap_or(0);
        if s_ck == 0 {
            return Err(SearchError::usage(format!(
                "T_final = {tf} h is reached before the first output sample"
            )));
        }
        let t_ck = s_ck as f64 * dt;
        let here = if base_dir.join("checkpoint.json").is_file() {
            Some(checkpoint_time(&base_dir).map_err(failed)?.0)
        } else {
            None
        };
        if here.is_some_and(|h| h > s_ck) {
            return Err(SearchError::usage(format!(
                "{}: the base run is past the start of T_final = {tf} h; remove the base directory to redo it",
                base_dir.display()
            )));
        }
        // The base run advances in legs, each ending in a checkpoint, so that one stopped before this hold's
        // start (a full-size path takes hours) resumes from its last leg, not from the previous hold's start. A
        // resumed run continues bit for bit (`crate::driver`), so the legs change no result.
        let mut here = here;
        for s_leg in base_legs(&sample_list, here.unwrap_or(0), s_ck, leg_steps) {
            let t_here = here.map_or(0.0, |h| h as f64 * dt);
            let t_leg = s_leg as f64 * dt;
            let options = RunOptions {
                force: true,
                progress: false,
                checkpoint_every: None,
                checkpoint_every_sim: Some(t_leg - t_here - 0.5 * dt),
                stop_after_checkpoints: Some(1),
                ..RunOptions::default()
            };
            emit(
                Channel::Progress,
                &format!(
                    "spinup critical: base run to t = {} s of {} s (T_final = {tf} h starts at {} s)",
                    fmt_time(t_leg),
                    fmt_time(t_ck),
                    fmt_time(starts[k])
                ),
            );
            let result = match here {
                Some(_) => resume_soft(&base_dir, &options),
                None => run_soft(&base_scene, &base_dir, &options),
            };
            match result {
                Err(crate::driver::RunError::Stopped { .. }) => {}
                Err(e) => return Err(failed(e)),
                Ok(_) => {
                    return Err(SearchError::failed(format!(
                        "{}: the base run ended before t = {t_leg} s",
                        base_dir.display()
                    )));
                }
            }
            here = Some(s_leg);
        }
        let mut hold_file = file.clone();
        if let Some(spinup) = hold_file.spinup.as_mut() {
            spinup.period_final_h = tf;
            spinup.t_final = starts[k];
        }
        hold_file.scene.t_end = starts[k] + hold;
        let mut snaps = keep(t_ck);
        for t in [starts[k], starts[k] + hold] {
            if snaps.last().is_none_or(|&last| t >= last + dt) {
                snaps.push(t);
            }
        }
        hold_file.output.times = Some(snaps);
        hold_file.output.snapshot_every = None;
        let hold_text = scene_text(&[], &hold_file);
        if dir.exists() {
            std::fs::remove_dir_all(&dir).map_err(|e| SearchError::failed(format!("{}: {e}", dir.display())))?;
        }
        branch_soft(&base_dir, &hold_text, &scene_dir, &dir).map_err(failed)?;
    }
    Ok(starts)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The base run of `--branch` stops on output samples, in legs no longer than asked, and reaches the hold start.
    #[test]
    fn base_run_legs_end_on_samples_and_reach_the_hold_start() {
        let samples: Vec<u64> = (0..=20).map(|k| k * 10).collect();
        // 0 → 200 in legs of at most 45 steps: the last sample within each reach
        assert_eq!(base_legs(&samples, 0, 200, 45), [40, 80, 120, 160, 200]);
        // a resumed base run starts from its checkpoint
        assert_eq!(base_legs(&samples, 120, 200, 45), [160, 200]);
        // legs shorter than the sample spacing still advance, one sample at a time
        assert_eq!(base_legs(&samples, 0, 30, 3), [10, 20, 30]);
        assert!(base_legs(&samples, 200, 200, 45).is_empty());
    }

    /// `--hold-s` sets the hold of a branched search only: without `--branch` it is refused by name, whatever its
    /// value, before any scene is read or hold run (it was once silently ignored and 21 full runs began).
    #[test]
    fn hold_s_without_branch_is_refused_naming_both_flags() {
        for hold in [-5.0, 2000.0] {
            let args = CriticalOptions {
                hold: Some(hold),
                ..CriticalOptions::new(
                    PathBuf::from("/nonexistent/scene.toml"),
                    2.5,
                    2.7,
                    0.1,
                    PathBuf::from("/nonexistent/out"),
                )
            };
            let e = match critical(&args) {
                Err(SearchError::Usage(m)) => m,
                other => panic!("expected a usage error, got {other:?}"),
            };
            assert!(
                e.contains("--hold-s") && e.contains("needs --branch") && !e.contains('\n'),
                "{e}"
            );
        }
    }
}
