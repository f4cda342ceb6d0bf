//! Campaigns past one machine without a distributed system of our own: deterministic shards of the grid for any
//! scheduler's job array (Slurm, PBS, GNU parallel) and the merge of their run directories into one `campaign.csv`.
//! (The job scripts themselves, and the runs over MPI ranks, are the `rubblepile` binary's, not the library's.)
//!
//! Shard `I/N` (0 ≤ I < N) runs the grid points whose index k (in the grid's order: targets, projectiles, angles,
//! seeds) has k mod N = I, so N shards cover the grid exactly once and interleave long and short runs. A sharded
//! campaign keeps its index in `campaign.shard-I-of-N.csv` (shards never write the same file); `rubblepile
//! campaign merge DIR` rebuilds `campaign.csv` from the run directories themselves, so it is right whatever
//! shards ran, died or ran twice.

use std::path::Path;
use std::str::FromStr;
use std::time::Instant;

use super::*;

/// One of N deterministic parts of a grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Which part, 0-based (`SLURM_ARRAY_TASK_ID` of an array `0-(N-1)`).
    pub index: usize,
    /// How many parts.
    pub count: usize,
}

impl FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Shard, String> {
        let bad = || format!("--shard: expected I/N with 0 <= I < N (e.g. 0/8), got {s:?}");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count): (usize, usize) = (
            i.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl Shard {
    /// Whether grid point `k` belongs to this shard.
    pub fn contains(&self, k: usize) -> bool {
        k % self.count == self.index
    }

    /// The shard's own index file.
    pub fn index_file(&self) -> String {
        format!("campaign.shard-{}-of-{}.csv", self.index, self.count)
    }
}

/// The cause and numbers of the run in `dir` when its summary says it failed (a directory [`decide`] would start
/// afresh: it has no checkpoint).
fn failed_run(dir: &Path) -> Option<(String, RunNumbers)> {
    let text = std::fs::read_to_string(dir.join("summary.json")).ok()?;
    let summary = serde_json::from_str::<serde_json::Value>(&text).ok()?;
    let status = summary.get("status")?.as_str()?;
    let cause = status.trim_start_matches("failed").trim_start_matches(':').trim();
    status
        .starts_with("failed")
        .then(|| (one_line(cause), RunNumbers::from_summary_text(&text)))
}

/// The campaign whose directory is `dir` (from the campaign file recorded there, [`CAMPAIGN_SOURCE`]).
pub fn campaign_of_dir(dir: &Path) -> Result<Campaign, CampaignError> {
    let pointer = dir.join(CAMPAIGN_SOURCE);
    let text = std::fs::read_to_string(&pointer).map_err(|e| crate::io::scene_file::SceneError::Read {
        file: pointer.display().to_string(),
        reason: format!("{e} (is {} a campaign directory?)", dir.display()),
    })?;
    let mut campaign = load_campaign(Path::new(text.trim()))?;
    // The directory given wins over the file's `out` (the campaign may have been run with --out).
    campaign.out = dir.to_path_buf();
    Ok(campaign)
}

/// Rebuilds `campaign.csv` of the campaign directory `dir` from its run directories; returns the report (every
/// run `Skip`ped, as nothing ran). Refused at once ([`CampaignError::Locked`]) while a campaign or one of its shards
/// writes `dir`.
pub fn merge_campaign(dir: &Path) -> Result<CampaignReport, CampaignError> {
    let started = Instant::now();
    let campaign = campaign_of_dir(dir)?;
    // The index is rewritten: not while a campaign or a shard writes the directory.
    let _lock = lock_campaign_dir(dir, None)?;
    // What each run directory shows by itself: completed, failed, a different run (conflict), or pending.
    let (mut runs, _) = plan_runs(&campaign, None);
    for r in &mut runs {
        if r.action == Action::Start
            && let Some((cause, numbers)) = failed_run(&dir.join(&r.name))
        {
            (r.status, r.numbers) = (RunStatus::Failed(cause), Some(numbers));
        }
        r.action = Action::Skip;
    }
    index::write_campaign_csv(dir, CAMPAIGN_CSV, &campaign.points, &runs)?;
    Ok(CampaignReport {
        runs,
        wall_seconds: started.elapsed().as_secs_f64(),
    })
}
