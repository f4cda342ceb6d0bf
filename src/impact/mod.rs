//! Impact experiments on rubble-pile targets (Roig03 §3, Tables 1–2).
//!
//! - [`target`]: the Monte-Carlo rubble-pile builder and its relaxation to a rigidly rotating pile;
//! - [`projectile`]: the projectiles P1–P3 and the impact geometry;
//! - [`geometry`]: aiming off the centre (impact parameter, impact angle to the surface normal), projectile spin and attitude;
//! - [`pile`]: rubble-pile projectiles (a whole pile thrown at the target);
//! - [`run`]: one impact run (target + projectile → run directory → [`crate::driver::run_scene`]);
//! - [`campaign`]: a grid of impact runs (targets × projectiles × angles × seeds) from a campaign file, run
//!   in parallel, resumable, summarised in `campaign.csv`;
//! - [`flyby`]: a tidal flyby of a pile past a planet (`rubblepile flyby`);
//! - [`problems`]: the canonical problems of the ellipsoid model (free top, bouncing pair, N30 impact, N-body
//!   tests), shared by the tests and the benchmarks.

pub mod campaign;
pub mod error;
pub mod flyby;
pub mod geometry;
pub mod pile;
pub mod problems;
pub mod projectile;
pub mod run;
pub mod settle;
pub mod target;
pub mod target_checkpoint;
pub mod target_spec;
