#![warn(missing_docs)]
//! rubblepile — dynamics of rubble-pile asteroids.
//!
//! The core is the interacting-ellipsoids model of Roig et al. (2003, Icarus 165) ("Roig03"):
//! rigid triaxial fragments with a Gaussian-overlap contact potential, monopole gravity,
//! quaternion attitudes constrained by Lagrange multipliers, a Rayleigh point-dissipation function,
//! integrated by an adaptive Bulirsch–Stoer integrator. Beside it, two granular engines: soft spheres (Zhang et al.
//! 2017, "Zhang17") and hard spheres (Richardson et al. 2011, "Richardson11").
//!
//! # Layers
//!
//! Imports only go down: a module may use the modules of lower layers, never those of its own layer or above, so
//! there is no import cycle and no engine sees the driver or the analysis. `tests/layers.rs` reads every `crate::`
//! path in `src/` and checks this table (the table below is what it reads).
//!
//! - **L0**: `math`, `bits`, `phase`, `named` — fixed-size linear algebra, bit-exact floats, wall time per phase of
//!   the hot loops (serial or parallel), the names users type for closed sets of values;
//! - **L1**: `random` — seeded random numbers (`rand_pcg`; seeds live in scene files);
//! - **L2**: `geometry`, `gravity`, `integrate`, `io` — shapes, walls and neighbour search; self-gravity; the ODE
//!   solvers and their canonical test problems; the scene-file floor and lossless formatting;
//! - **L3**: `engine` — the contract between an engine and the driver ([`engine::Engine`]);
//! - **L4**: `ellipsoid`, `granular` — the engines (interacting ellipsoids; soft and hard spheres), each with its scene
//!   schema, equations, outputs and [`engine::Engine`] implementation;
//! - **L5**: `driver` — the one run driver (schedule, outputs, checkpoints, resume, failures), the choice of engine;
//! - **L6**: `aggregate`, `impact` — builders of rubble piles and impact experiments on top of the engines and driver,
//!   with the canonical problems of the ellipsoid model;
//! - **L7**: `analysis` — science on finished runs that any run needs (fragment statistics, fits, clumps, spin-up
//!   diagnostics and the verdicts of searches, figures);
//! - **L8**: `render`, `experiment` — pictures of runs: ray-cast frames of ellipsoids and spheres, PNG and animated
//!   GIF; experiments that run many simulations and judge them with the analysis (the T_c,3 search).
//!
//! # Programs
//!
//! The programs are not the library's: they are the module tree of the `rubblepile` binary (`src/main.rs`), which
//! uses the library as `rubblepile::…` and its own modules as `crate::…`, again only downwards (`tests/layers.rs`
//! reads this list too, and checks that no library file names a program):
//!
//! - **P0**: `test_dirs` — the unit tests' temporary directories (test builds only);
//! - **P1**: `studies`, `choice` — the three papers' reports (Roig03, Zhang17, Richardson11), one room per paper, on top of
//!   `analysis`;
//! - **P2**: `bench`, `cluster` — benchmarks and timed systems on the canonical test problems (they plot with
//!   `analysis`' figures); campaigns launched on clusters (Slurm job-array scripts, MPI ranks);
//! - **P3**: `cli` — argument parsing and dispatch.

pub mod aggregate;
pub mod analysis;
pub mod bits;
pub mod driver;
pub mod ellipsoid;
pub mod engine;
pub mod experiment;
pub mod geometry;
pub mod granular;
pub mod gravity;
pub mod impact;
pub mod integrate;
pub mod io;
pub mod math;
pub mod named;
pub mod phase;
pub mod random;
pub mod render;
