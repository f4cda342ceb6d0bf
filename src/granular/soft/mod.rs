//! The soft-sphere discrete element method (SSDEM) of Zhang et al. (2017, Icarus 294, §2) ("Zhang17"):
//! spheres that touch through spring–dashpot–slider contacts (normal, sliding, twisting, rolling),
//! self-gravity by octree or direct summation, walls, and a kick–drift–kick leapfrog with a fixed step.
//!
//! - [`particle`]: the spheres; [`contact`]: the contact law (Eqs. 1–12); [`spring_frame`]: springs carried
//!   with the contact frame; [`forces`]: the forces of a step; [`pairs`]: the pair contacts (Verlet list,
//!   springs, the same sums on any number of threads); [`leapfrog`]: the integrator; [`respa`]: self-gravity
//!   every `k` steps (multiple time stepping);
//! - [`advise`]: `k_N` and the step for a requested maximum overlap; [`packing`]: lattice aggregates;
//!   [`scene`]: the `kind = "soft-spheres"`
//!   scene file; [`run`]: the engine as the run driver sees it (outputs, checkpoint state); `driver::branch`: a run continued from another's
//!   checkpoint under a new scene; [`spinup`]: the `[spinup]` forcing
//!   (Zhang17 §2.3.4).

pub mod advise;
pub mod contact;
pub mod forces;
pub mod leapfrog;
pub mod ordered_sum;
pub mod packing;
pub mod pairs;
pub mod particle;
pub mod respa;
pub mod run;
pub mod scene;
pub mod spinup;
pub mod spinup_diagnostics;
pub mod spring_frame;
pub mod stress;
