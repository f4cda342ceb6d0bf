//! Where a campaign runs: on this machine's threads ([`run_campaign`]), or, when the process was started by
//! `mpirun` and rubblepile was built with the `mpi` cargo feature, over MPI ranks (`cluster::mpi`, feature `mpi`):
//! rank 0 hands runs out one at a time and keeps `campaign.csv`, the other ranks run them. The default build needs
//! no MPI; a default build started by `mpirun` with several ranks refuses to run (every rank would run the whole
//! grid into the same directories) and says how to build with MPI.

use rubblepile::impact::campaign::{Campaign, CampaignError, CampaignOptions, CampaignReport, run_campaign};

/// The number of ranks `mpirun` (Open MPI, MPICH, PMIx launchers) says this process belongs to, if any.
pub fn launcher_world_size() -> Option<usize> {
    ["OMPI_COMM_WORLD_SIZE", "PMIX_SIZE", "PMI_SIZE"]
        .iter()
        .find_map(|k| std::env::var(k).ok()?.parse().ok())
}

/// Ranks of this job on this node (for sizing each rank's thread pool), if the launcher says.
pub fn launcher_local_size() -> Option<usize> {
    ["OMPI_COMM_WORLD_LOCAL_SIZE", "MPI_LOCALNRANKS"]
        .iter()
        .find_map(|k| std::env::var(k).ok()?.parse().ok())
}

/// Threads for each rank's rayon pool: `threads_per_rank`, or this node's cores shared among its ranks.
pub fn threads_per_rank(threads_per_rank: Option<usize>) -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    threads_per_rank
        .unwrap_or_else(|| cores / launcher_local_size().unwrap_or(1).max(1))
        .max(1)
}

/// Runs `campaign` on threads, or over MPI when launched by `mpirun` (see the module docs). `Ok(None)` on the
/// ranks that only ran runs (rank 0 reports).
pub fn run_campaign_anywhere(
    campaign: &Campaign,
    options: &CampaignOptions,
) -> Result<Option<CampaignReport>, CampaignError> {
    let ranks = launcher_world_size().unwrap_or(1);
    #[cfg(feature = "mpi")]
    if ranks > 1 {
        return super::mpi::run_campaign_mpi(campaign, options);
    }
    #[cfg(not(feature = "mpi"))]
    if ranks > 1 {
        return Err(rubblepile::io::scene_file::SceneError::Invalid {
            file: campaign.name.clone(),
            field: "mpirun".into(),
            message: format!(
                "started as one of {ranks} MPI ranks, but this rubblepile was built without MPI: build it with \
                 `cargo build --release --features mpi` (needs Open MPI and libclang), or run without mpirun"
            ),
        }
        .into());
    }
    run_campaign(campaign, options).map(Some)
}
