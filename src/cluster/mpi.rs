//! Campaigns over MPI (cargo feature `mpi`, the `mpi` crate over the system's MPI library): `mpirun -n K
//! rubblepile campaign FILE`.
//!
//! Rank 0 is the coordinator and runs no impact: it decides what each grid point needs (as the threaded runner
//! does: skip, resume, start), hands the runs out one at a time to whichever rank asks (dynamic, so long runs do not
//! hold short ones back), and is the only writer of `campaign.csv` (atomically, after every event), holding the
//! campaign directory's lock ([`lock_campaign_dir`]) while it coordinates. Ranks 1…K−1 run
//! the runs they are given through the same [`run_point`] as the threaded runner, so every run directory holds the
//! same bytes whichever rank ran it. While waiting, rank 0 polls with short sleeps instead of MPI's busy-waiting
//! receive, so it costs no core.
//!
//! Messages are short UTF-8 texts on one tag: a worker sends `ready`, then `done <k> <stopped> <status>` after each
//! run; rank 0 answers `run <k>` or `stop`.
//!
//! A rank killed mid-run: Open MPI (4.x, without its ULFM fault-tolerance extension) then ends the whole job, so
//! the other ranks' current runs stop too. Nothing is lost: every run writes its checkpoints and outputs
//! atomically and `campaign.csv` is replaced atomically, so the next `mpirun … campaign FILE` skips the completed
//! runs, resumes the checkpointed ones and restarts the rest.

use std::time::{Duration, Instant};

use ::mpi::traits::*;
use rubblepile::impact::campaign::{
    CAMPAIGN_CSV, Campaign, CampaignError, CampaignOptions, CampaignReport, RunNumbers, RunStatus, decide,
    lock_campaign_dir, plan_runs, run_point, write_campaign_csv,
};
use rubblepile::io::messages::{Channel, emit};

const TAG: i32 = 7;

/// Grids up to this size get `campaign.csv` rewritten at every event; larger ones at most once a second (and at
/// the end): the index grows with the grid and is rewritten whole, so at 10⁴ runs and hundreds of workers writing
/// it per event would make rank 0 the bottleneck (analysis/campaign_scaling/README.md).
pub const EVERY_EVENT_UP_TO: usize = 2000;

fn send(world: &::mpi::topology::SimpleCommunicator, rank: i32, text: &str) {
    world.process_at_rank(rank).send_with_tag(text.as_bytes(), TAG);
}

fn parse_status(s: &str) -> RunStatus {
    match s {
        "completed" => RunStatus::Completed,
        "pending" => RunStatus::Pending,
        "running" => RunStatus::Running,
        _ => RunStatus::Failed(s.strip_prefix("failed: ").unwrap_or(s).to_string()),
    }
}

/// Runs `campaign` over the ranks of `MPI_COMM_WORLD`; `Some(report)` on rank 0, `None` on the others.
pub fn run_campaign_mpi(
    campaign: &Campaign,
    options: &CampaignOptions,
) -> Result<Option<CampaignReport>, CampaignError> {
    let universe = ::mpi::initialize().ok_or_else(|| rubblepile::io::scene_file::SceneError::Invalid {
        file: campaign.name.clone(),
        field: "mpirun".into(),
        message: "MPI could not be initialised".into(),
    })?;
    let world = universe.world();
    if world.rank() == 0 {
        // Rank 0 alone locks the campaign directory; each worker rank locks the run directory it writes (in
        // `execute`). Refused, it sends the workers home before it says so: left waiting, they would hang the job.
        let out = &campaign.out;
        let locked = std::fs::create_dir_all(out)
            .map_err(|source| CampaignError::Io {
                path: out.clone(),
                source,
            })
            .and_then(|_| lock_campaign_dir(out, options.shard));
        let _lock = match locked {
            Ok(lock) => lock,
            Err(e) => {
                dismiss(&world);
                return Err(e);
            }
        };
        coordinate(&world, campaign, options).map(Some)
    } else {
        work(&world, campaign, options);
        Ok(None)
    }
}

/// Answers every worker's first `ready` with `stop`, so that all ranks end when rank 0 cannot coordinate.
fn dismiss(world: &::mpi::topology::SimpleCommunicator) {
    for rank in 1..world.size() {
        let _ = world.process_at_rank(rank).receive_vec_with_tag::<u8>(TAG);
        send(world, rank, "stop");
    }
}

fn work(world: &::mpi::topology::SimpleCommunicator, campaign: &Campaign, options: &CampaignOptions) {
    send(world, 0, "ready");
    loop {
        let (msg, _) = world.process_at_rank(0).receive_vec_with_tag::<u8>(TAG);
        let text = String::from_utf8_lossy(&msg).into_owned();
        let Some(k) = text.strip_prefix("run ").and_then(|k| k.parse::<usize>().ok()) else {
            return;
        };
        let point = &campaign.points[k];
        let dir = campaign.out.join(&point.name);
        let action = decide(&dir, &point.plan).0;
        let (status, stopped, _) = run_point(point, &dir, &action, &options.run);
        send(world, 0, &format!("done {k} {stopped} {status}"));
    }
}

fn coordinate(
    world: &::mpi::topology::SimpleCommunicator,
    campaign: &Campaign,
    options: &CampaignOptions,
) -> Result<CampaignReport, CampaignError> {
    let started = Instant::now();
    let out = &campaign.out;
    let points = &campaign.points;
    let (mut runs, todo) = plan_runs(campaign, options.shard);
    let index_file = options.shard.map_or(CAMPAIGN_CSV.to_string(), |s| s.index_file());
    write_campaign_csv(out, &index_file, points, &runs)?;
    let workers = world.size() - 1;
    if options.verbose {
        emit(
            Channel::Out,
            &format!(
                "campaign over MPI: {} runs to do of {}, {workers} worker ranks (rank 0 coordinates)",
                todo.len(),
                runs.len()
            ),
        );
    }
    let (mut next, mut done, mut active) = (0, 0, workers);
    let mut last_write = Instant::now();
    while active > 0 {
        let Some(status) = world.any_process().immediate_probe_with_tag(TAG) else {
            std::thread::sleep(Duration::from_millis(2));
            continue;
        };
        let from = status.source_rank();
        let (msg, _) = world.process_at_rank(from).receive_vec_with_tag::<u8>(TAG);
        let text = String::from_utf8_lossy(&msg).into_owned();
        if let Some(rest) = text.strip_prefix("done ") {
            let mut parts = rest.splitn(3, ' ');
            let k: usize = parts.next().and_then(|k| k.parse().ok()).unwrap_or(usize::MAX);
            let stopped = parts.next() == Some("true");
            if let Some(r) = runs.get_mut(k) {
                r.status = parse_status(parts.next().unwrap_or("failed: no status"));
                r.stopped = stopped;
                let summary = std::fs::read_to_string(out.join(&r.name).join("summary.json")).ok();
                r.numbers = summary.as_deref().map(RunNumbers::from_summary_text);
                done += 1;
                if options.verbose {
                    emit(
                        Channel::Out,
                        &format!("[{done}/{}] {} (rank {from}): {}", todo.len(), r.name, r.status),
                    );
                }
            }
        }
        match todo.get(next) {
            Some(&i) => {
                next += 1;
                runs[i].status = RunStatus::Running;
                send(world, from, &format!("run {i}"));
            }
            None => {
                send(world, from, "stop");
                active -= 1;
            }
        }
        if points.len() <= EVERY_EVENT_UP_TO || last_write.elapsed() >= Duration::from_secs(1) {
            write_campaign_csv(out, &index_file, points, &runs)?;
            last_write = Instant::now();
        }
    }
    write_campaign_csv(out, &index_file, points, &runs)?;
    Ok(CampaignReport {
        runs,
        wall_seconds: started.elapsed().as_secs_f64(),
    })
}
