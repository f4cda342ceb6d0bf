//! Campaigns launched past one machine: a Slurm job-array script running a campaign as shards ([`slurm`]), and
//! where `rubblepile campaign FILE` runs, on this machine's threads or over the MPI ranks `mpirun` started
//! ([`launch`]; the MPI runner with the cargo feature `mpi`). On top of the library's campaigns
//! ([`rubblepile::impact::campaign`]: the grid, its shards, the runs and `campaign.csv`).

pub mod launch;
#[cfg(feature = "mpi")]
pub mod mpi;
pub mod slurm;
