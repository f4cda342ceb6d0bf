//! Branching a soft-sphere run: a new run that starts from another run's checkpoint under a different scene
//! whose physics agrees with the first run's up to the checkpoint (the same particles, contacts, gravity, output
//! grid up to that time and spin-up path up to that time). It saves re-simulating a shared history, as in the
//! search for Zhang17's third critical spin limit (§3.3.3), where every hold run follows the same spin-up path
//! until its own final period.
//!
//! The branch directory gets the new scene as `scene.toml`, the parent's `timeseries.csv` and `spinup.csv`
//! (cut back to the checkpoint when the branch is resumed), the parent's snapshots from before the checkpoint (the
//! grids agree up to it, so they are the branch's own; `resume` refuses a directory without them; a snapshot the new
//! grid puts at the checkpoint's own sample is written from the checkpoint's state) and the parent's
//! `checkpoint.json` with the scene hash of the new scene; [`crate::driver::runner::resume_soft`] then carries it on. Whether the two
//! scenes really agree up to the checkpoint is the caller's promise; what can be checked here is checked: the
//! new scene must parse, hold the same number of particles, and put an output sample at the checkpoint's step
//! with the same index.

use std::path::Path;

use super::runner::RunError;
use crate::bits::fnv1a_hex;
use crate::engine::{Engine, Resumed};
use crate::granular::soft::run::{SoftEngine, SoftSummary, sample_steps};
use crate::granular::soft::scene::parse_soft_scene;
use crate::io::checkpoint::CHECKPOINT_FILE;

/// Errors of branching: those of a soft-sphere run.
type BranchError = RunError<SoftSummary>;

/// The step and time (s) of the checkpoint in `dir`.
pub fn checkpoint_time(dir: &Path) -> Result<(u64, f64), BranchError> {
    let v = read_checkpoint(dir)?;
    let step = v["engine"]["step"].as_u64();
    let t = v["t_seconds"].as_f64();
    step.zip(t).ok_or_else(|| {
        bad(format!(
            "{}: no engine.step/t_seconds (not a soft-sphere checkpoint of this build)",
            dir.join(CHECKPOINT_FILE).display()
        ))
    })
}

fn bad(m: String) -> BranchError {
    RunError::BadCheckpoint(m)
}

fn read_checkpoint(dir: &Path) -> Result<serde_json::Value, BranchError> {
    let p = dir.join(CHECKPOINT_FILE);
    let text = std::fs::read_to_string(&p).map_err(|e| bad(format!("{}: {e}", p.display())))?;
    serde_json::from_str(&text).map_err(|e| bad(format!("{}: {e}", p.display())))
}

/// Writes a branch of the run in `parent` (stopped at its checkpoint) into the new, empty directory `dir`, under
/// the scene `scene_text` (its `particles_file`, if relative, resolved against `scene_dir`). Resume `dir` to run
/// the branch.
///
/// Errors name what disagrees: the scene does not parse, the particle count differs, or the new scene's output
/// grid has no sample at the checkpoint's step with the checkpoint's index.
pub fn branch_soft(parent: &Path, scene_text: &str, scene_dir: &Path, dir: &Path) -> Result<(), BranchError> {
    let mut ck = read_checkpoint(parent)?;
    // The branch's scene copy stands alone as a run's does (crate::io::standalone).
    let scene_text = &crate::io::standalone::with_absolute_inputs(scene_text, scene_dir);
    let name = dir.join("scene.toml").display().to_string();
    let scene = parse_soft_scene(scene_text, &name, Some(scene_dir)).map_err(|e| bad(e.to_string()))?;
    let n_state = ck["engine"]["state"].as_array().map_or(0, Vec::len);
    if n_state != 15 * scene.particles.len() {
        return Err(bad(format!(
            "{name}: {} particles, the parent's checkpoint holds {}",
            scene.particles.len(),
            n_state / 15
        )));
    }
    let step = ck["engine"]["step"].as_u64().unwrap_or(u64::MAX);
    let index = ck["next_sample"].as_u64().unwrap_or(0) as usize;
    let plan = sample_steps(&scene);
    if index == 0 || plan.get(index - 1).map(|s| s.0) != Some(step) {
        return Err(bad(format!(
            "{name}: its output grid has no sample number {} at step {step} (the parent's checkpoint)",
            index.saturating_sub(1)
        )));
    }
    ck["scene_hash"] = serde_json::Value::String(fnv1a_hex(scene_text.as_bytes()));
    ck["scene_base_dir"] = serde_json::Value::String(scene_dir.display().to_string());
    use crate::io::safe_write::{copy_atomic, ensure_dir, write_atomic};
    let io = |p: &Path, e: std::io::Error| bad(crate::io::safe_write::describe(p, &e));
    let snapshot = |k: usize| dir.join("snapshots").join(format!("{k}.csv"));
    ensure_dir(&dir.join("snapshots")).map_err(|e| io(&dir.join("snapshots"), e))?;
    write_atomic(&dir.join("scene.toml"), scene_text).map_err(|e| io(&dir.join("scene.toml"), e))?;
    for f in ["timeseries.csv", "spinup.csv"] {
        let from = parent.join(f);
        if from.is_file() {
            copy_atomic(&from, &dir.join(f)).map_err(|e| io(&dir.join(f), e))?;
        }
    }
    // The parent's snapshots from before the checkpoint are the branch's: the grids agree up to it.
    let mut at_checkpoint = None;
    for (i, k) in plan[..index]
        .iter()
        .enumerate()
        .filter_map(|(i, &(_, k))| Some((i, k?)))
    {
        let (from, to) = (parent.join("snapshots").join(format!("{k}.csv")), snapshot(k));
        if i + 1 == index && !from.is_file() {
            // The branch's grid may put a snapshot at the checkpoint's own sample, where the parent's has none.
            at_checkpoint = Some(k);
            continue;
        }
        copy_atomic(&from, &to).map_err(|e| io(&to, e))?;
    }
    let text = serde_json::to_string_pretty(&ck).expect("checkpoint serialises");
    crate::io::safe_write::write_atomic_durable(&dir.join(CHECKPOINT_FILE), text)
        .map_err(|e| io(&dir.join(CHECKPOINT_FILE), e))?;
    if let Some(k) = at_checkpoint {
        // The checkpoint's state is that sample's state (a run writes a sample's snapshot, then checkpoints), so the
        // engine restored from it writes the snapshot the branch's own run would have written there.
        let c = super::runner::read_checkpoint::<SoftEngine>(dir)?;
        let mut engine =
            SoftEngine::from_scene_text(scene_text, &name, Some(scene_dir)).map_err(|e| bad(e.to_string()))?;
        let at = Resumed {
            t: c.t,
            samples_done: c.next_sample,
        };
        engine.restore(c.engine, dir, at).map_err(|e| bad(e.to_string()))?;
        engine.write_snapshot(&snapshot(k)).map_err(|e| io(&snapshot(k), e))?;
    }
    Ok(())
}
