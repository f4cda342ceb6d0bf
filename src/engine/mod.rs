//! The contract between a physics engine and the one run driver (`driver`).
//!
//! An engine (the ellipsoids of Roig03, the soft spheres of Zhang17, the hard spheres of Richardson11) knows its
//! state, how to advance it to a time, and what its outputs look like: the columns of `timeseries.csv`, the rows of a
//! snapshot, the fields of `summary.json`, the state a checkpoint must hold to continue bit for bit. The driver owns
//! everything else, once for all engines: the output directory, the sample schedule's walk, the time series file,
//! snapshots, progress, wall-clock and simulated-time checkpoints (written atomically), `resume`, the summary file
//! and failure handling with the last good state saved.
//!
//! This module sits on the low floor of the crate (beside [`crate::io`]): engines implement [`Engine`], the driver
//! above them calls it, and nothing here knows any engine.

pub mod schedule;

use std::path::Path;

use serde::Serialize;
use serde::de::DeserializeOwned;

pub use schedule::{Sample, Schedule};

use crate::math::Vec3;

/// The `timeseries.csv` columns of the total linear momentum (kg m/s) and angular momentum (kg m²/s), named alike
/// by every engine that writes them.
pub const MOMENTUM_COLUMNS: [&str; 6] = ["px", "py", "pz", "lx", "ly", "lz"];

/// The values of [`MOMENTUM_COLUMNS`]: the linear momentum `p`, then the angular momentum `l`.
pub fn momentum_values(p: &Vec3, l: &Vec3) -> [f64; 6] {
    [p.x, p.y, p.z, l.x, l.y, l.z]
}

/// The `N` column names of `parts` in order, for lists that share a group such as [`MOMENTUM_COLUMNS`]; in a
/// `const`, parts that do not add up to `N` names stop the build.
///
/// ```
/// use rubblepile::engine::column_names;
/// const NAMES: [&str; 3] = column_names(&[&["t"], &["x", "y"]]);
/// assert_eq!(NAMES, ["t", "x", "y"]);
/// ```
pub const fn column_names<const N: usize>(parts: &[&[&'static str]]) -> [&'static str; N] {
    let mut names = [""; N];
    let (mut n, mut p) = (0, 0);
    while p < parts.len() {
        let mut k = 0;
        while k < parts[p].len() {
            names[n] = parts[p][k];
            n += 1;
            k += 1;
        }
        p += 1;
    }
    assert!(n == N, "the parts do not add up to N column names");
    names
}

/// One particle of a snapshot, the same for every engine, for output formats that know no engine
/// (`driver::formats`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParticleView {
    /// Index in the scene.
    pub id: usize,
    /// Mass (kg).
    pub mass: f64,
    /// Centre (m).
    pub position: Vec3,
    /// Velocity of the centre (m/s).
    pub velocity: Vec3,
    /// Spin in the world frame (rad/s).
    pub spin_world: Vec3,
    /// Semi-axes A ≥ B ≥ C (m); a sphere's radius three times.
    pub axes: Vec3,
    /// Rotation from the body frame to the world frame (the identity for spheres).
    pub rotation: crate::math::Mat3,
}

impl ParticleView {
    /// A sphere of `radius` (m): axes all equal to it, no rotation.
    pub fn sphere(id: usize, mass: f64, radius: f64, position: Vec3, velocity: Vec3, spin_world: Vec3) -> Self {
        ParticleView {
            id,
            mass,
            position,
            velocity,
            spin_world,
            axes: Vec3::repeat(radius),
            rotation: crate::math::Mat3::identity(),
        }
    }
}

/// A contact between two particles at a snapshot (a force chain's link).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactLine {
    /// First particle (index into the snapshot's particles).
    pub i: usize,
    /// Second particle.
    pub j: usize,
    /// Magnitude of the normal force between them (N).
    pub normal_force: f64,
}

/// A wall (or other fixed-shape surface) at a snapshot, where its motion has carried it.
#[derive(Debug, Clone, PartialEq)]
pub struct NamedSurface {
    /// Name (`wall0`, `wall1`, …), also the name of its file.
    pub name: String,
    /// The surface (m).
    pub mesh: crate::geometry::mesh::SurfaceMesh,
}

/// Everything a snapshot shows, the same for every engine: the particles, and the contact network and surfaces of
/// the engines that have them. Output formats (`driver::formats`) and pictures read only this.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SnapshotView {
    /// Simulated time (s).
    pub t: f64,
    /// Whether the particles are spheres (their axes are one radius) rather than triaxial ellipsoids.
    pub spheres: bool,
    /// The particles.
    pub particles: Vec<ParticleView>,
    /// Particle–particle contacts (soft spheres; `None` for engines without a contact network).
    pub contacts: Option<Vec<ContactLine>>,
    /// Walls (hard spheres; empty for the other engines).
    pub surfaces: Vec<NamedSurface>,
    /// Extra per-particle scalars found by an analysis (name, one value per particle), e.g. `bound`.
    pub extra: Vec<(String, Vec<f64>)>,
}

/// How far the particles reach from `from` (m): the largest distance to a particle's centre plus its largest
/// semi-axis; 1 m without particles. Unbounded walls are drawn this far.
pub fn reach(particles: &[ParticleView], from: &Vec3) -> f64 {
    let r = particles
        .iter()
        .map(|p| (p.position - from).norm() + p.axes.max())
        .fold(0.0, f64::max);
    if r > 0.0 && r.is_finite() { r } else { 1.0 }
}

/// Reads a sphere engine's snapshot (`t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz`, other columns ignored): its time
/// (s; 0 for a file without particles) and particles.
pub fn read_sphere_snapshot(path: &Path) -> Result<(f64, Vec<ParticleView>), EngineError> {
    const COLUMNS: [&str; 13] = [
        "t", "id", "mass", "radius", "x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz",
    ];
    let records = crate::io::particles::read_particles(path, &COLUMNS, &[]).map_err(|e| EngineError::File {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    let t = records.first().map_or(0.0, |r| r.values[0]);
    let particles = records
        .iter()
        .map(|r| {
            let v = &r.values;
            let vec3 = |k: usize| Vec3::new(v[k], v[k + 1], v[k + 2]);
            ParticleView::sphere(v[1] as usize, v[2], v[3], vec3(4), vec3(7), vec3(10))
        })
        .collect();
    Ok((t, particles))
}

/// Why an engine could not be set up from a scene, or could not continue from a checkpoint's state.
#[derive(Debug, thiserror::Error)]
pub enum EngineError {
    /// The scene is invalid (one line naming the file and the field).
    #[error(transparent)]
    Scene(#[from] crate::io::scene_file::SceneError),
    /// The scene is valid but the engine cannot be built from it (e.g. the integrator refuses its tolerances).
    #[error("{0}")]
    Setup(String),
    /// The checkpoint's state does not fit the scene (counts, lengths, non-finite values, another method).
    #[error("{0}")]
    State(String),
    /// An output file to continue is missing, unreadable or shorter than at the checkpoint.
    #[error("{}: {reason}", .path.display())]
    File {
        /// The file.
        path: std::path::PathBuf,
        /// What is wrong.
        reason: String,
    },
}

/// Why an engine stopped: the cause, one line (e.g. `"integrator error: step size underflow at t = …"`). The
/// engine keeps its last good state and writes it when asked ([`Engine::write_last_good_state`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    /// The cause, as reported to the user.
    pub cause: String,
    /// Whether the advance stopped because the wall-clock deadline of [`Engine::set_deadline`] passed (the run's
    /// budget, not a broken state): the driver then stops cleanly at the sample before.
    pub deadline: bool,
}

impl Failure {
    /// A failure with this cause.
    pub fn new(cause: impl Into<String>) -> Self {
        Failure {
            cause: cause.into(),
            deadline: false,
        }
    }

    /// The advance stopped at the deadline of [`Engine::set_deadline`] (at `t`, s).
    pub fn deadline(t: f64) -> Self {
        Failure {
            cause: format!("the wall-clock deadline passed at t = {t} s"),
            deadline: true,
        }
    }
}

/// What went wrong while an engine sampled its state: the run broke ([`Failure`]) or one of the engine's own
/// output files could not be written.
#[derive(Debug)]
pub enum SampleError {
    /// The sampled state is broken (non-finite, constraint violated): the run stops.
    Failed(Failure),
    /// Writing an engine-owned file (a track, a log) failed.
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

impl From<Failure> for SampleError {
    fn from(f: Failure) -> Self {
        SampleError::Failed(f)
    }
}

/// How a run ended, for [`Engine::summary`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outcome<'a> {
    /// Every sample was reached.
    Completed,
    /// The run stopped with this failure.
    Failed(&'a Failure),
}

/// What the driver tells an engine when it continues from a checkpoint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resumed {
    /// Simulated time of the checkpoint (s).
    pub t: f64,
    /// Time-series samples written before the checkpoint (the index of the next sample).
    pub samples_done: u64,
}

/// The summary an engine writes to `summary.json`, as the command line reports it.
pub trait RunReport: Serialize + std::fmt::Debug + Clone {
    /// One line for the terminal (status, time reached, the errors beside the wall time).
    fn one_line(&self) -> String;
    /// Warnings to print after the line (e.g. contact-barrier overruns); none by default.
    fn warnings(&self) -> Vec<String> {
        Vec::new()
    }
}

/// A physics engine as the run driver sees it. The driver calls, in order: [`Engine::open_outputs`] (fresh run) or
/// [`Engine::restore`] (resume); then for each remaining sample [`Engine::advance`], [`Engine::sample`] and, at
/// snapshot times, [`Engine::write_snapshot`]; [`Engine::save`] when a checkpoint is due; and [`Engine::summary`] at
/// the end. On a [`Failure`] it calls [`Engine::write_last_good_state`] and [`Engine::summary`] with
/// [`Outcome::Failed`]. The driver runs all of this on a worker thread of rayon's pool, hence `Send`.
pub trait Engine: Sized + Send {
    /// The engine's `summary.json`.
    type Summary: RunReport + Send;
    /// Everything the engine needs to continue bit for bit, stored in `checkpoint.json` under `engine`.
    type State: Serialize + DeserializeOwned;

    /// The scene kind (`scene.kind` in a scene file), also recorded in checkpoints.
    const KIND: &'static str;

    /// Builds the engine from a scene file's text (`name` names it in errors; a relative input file named in the
    /// scene is resolved against `base_dir`). Used by `resume`, on the run's `scene.toml` copy.
    fn from_scene_text(text: &str, name: &str, base_dir: Option<&Path>) -> Result<Self, EngineError>;

    /// The scene text, copied to `scene.toml`.
    fn scene_source(&self) -> &str;

    /// The directory relative input files of the scene were read from, if any (recorded in checkpoints).
    fn scene_base_dir(&self) -> Option<&Path>;

    /// The requested end time (s).
    fn t_end(&self) -> f64;

    /// The current simulated time (s).
    fn time(&self) -> f64;

    /// Every output sample of the run, in time order (the last one ends the run).
    fn samples(&self) -> Vec<Sample>;

    /// The header line of `timeseries.csv`, with its newline.
    fn timeseries_header(&self) -> String;

    /// Creates the engine's own output files in `dir` (e.g. `tracks.csv`) for a fresh run.
    fn open_outputs(&mut self, dir: &Path) -> std::io::Result<()>;

    /// Advances the state to `to.t` (`index` is the sample's position in [`Engine::samples`]), calling
    /// `progress(t)` now and then with the simulated time reached.
    fn advance(&mut self, index: usize, to: &Sample, progress: &mut dyn FnMut(f64)) -> Result<(), Failure>;

    /// Checks and records the state at a sample, writes the engine's own per-sample files, and returns the
    /// time-series row (with its newline); `wall_seconds` is the run's wall-clock time so far.
    fn sample(&mut self, to: &Sample, wall_seconds: f64) -> Result<String, SampleError>;

    /// Writes the current state as a snapshot file.
    fn write_snapshot(&self, path: &Path) -> std::io::Result<()>;

    /// The particles of the current state, for the driver's extra snapshot formats.
    fn particles(&self) -> Vec<ParticleView>;

    /// Whether the engine's particles are spheres (for output formats: a radius rather than axes and attitude).
    const SPHERES: bool;

    /// Particle–particle contacts now (engines with a contact network, the soft spheres; `None` for the others).
    fn contacts(&self) -> Option<Vec<ContactLine>> {
        None
    }

    /// Walls now (engines with walls: the hard spheres).
    fn surfaces(&self) -> Vec<NamedSurface> {
        Vec::new()
    }

    /// What the state shows now ([`SnapshotView`]).
    fn view(&self) -> SnapshotView {
        SnapshotView {
            t: self.time(),
            spheres: Self::SPHERES,
            particles: self.particles(),
            contacts: self.contacts(),
            surfaces: self.surfaces(),
            extra: Vec::new(),
        }
    }

    /// What the snapshot file `path` (written by [`Engine::write_snapshot`] of a run of this scene) shows, its
    /// contacts and walls recomputed for the snapshot's state and time. Does not change the engine.
    fn view_of_snapshot(&self, path: &Path) -> Result<SnapshotView, EngineError>;

    /// Whether the scene itself asks for VTK snapshots (`[output] vtk = true`).
    fn scene_vtk(&self) -> bool {
        false
    }

    /// The most threads this run can use well: its work per parallel pass divided by the work a thread needs to
    /// pay for joining the pass. The driver runs the engine on at most this many threads of the pool it is given
    /// (a smaller pool of its own when needed), so that a small run does not get slower on a big node. The bits
    /// do not depend on it. Default: no limit.
    fn useful_threads(&self) -> usize {
        usize::MAX
    }

    /// The steps the whole run needs by the scene's own work estimate (integrator steps of the ellipsoids, fixed
    /// steps of the spheres), for the run's step budget ([`crate::io::run_budget`]): a scene estimated to need more
    /// than its budget is refused before it starts. Default: no estimate.
    fn estimated_steps(&self) -> Option<f64> {
        None
    }

    /// Steps taken by the run so far, those before its checkpoint included (the measure of
    /// [`Engine::estimated_steps`]). Default: 0 (no budget is kept).
    fn steps_taken(&self) -> u64 {
        0
    }

    /// Caps the steps the next [`Engine::advance`] may take at `most` (what is left of the run's budget): an engine
    /// whose steps between two samples are not known in advance (the ellipsoids' adaptive integrator) fails that
    /// advance beyond it rather than crawl on. Default: nothing (fixed steps: the budget is checked at samples).
    fn limit_steps(&mut self, _most: u64) {}

    /// Makes the next [`Engine::advance`] calls stop with [`Failure::deadline`] once the wall clock passes
    /// `deadline` (`None`: never), so that a run's wall-clock budget holds within a long sample interval too; the
    /// state is then past the last sample and the driver continues from what it saved there. Default: nothing.
    fn set_deadline(&mut self, _deadline: Option<std::time::Instant>) {}

    /// The run's error measure up to its last sample, for the progress lines of a batch log: its name and value
    /// (the relative energy error its summary reports, or the bookkeeping residual where energy is exchanged on
    /// purpose). Default: none.
    fn error_so_far(&self) -> Option<(&'static str, f64)> {
        None
    }

    /// Writes the last good state (after a [`Failure`]) in the snapshot format; returns its time (s).
    fn write_last_good_state(&self, path: &Path) -> std::io::Result<f64>;

    /// The summary; `samples` is the number of time-series rows written, `wall_seconds` the run's wall-clock time.
    fn summary(&self, outcome: Outcome<'_>, samples: u64, wall_seconds: f64) -> Self::Summary;

    /// The state to checkpoint (flushing the engine's own files first, so that what the state counts is on disk).
    fn save(&mut self) -> std::io::Result<Self::State>;

    /// Continues from a checkpoint's state: restores it and reopens the engine's own files in `dir`, cut back to
    /// what they held at the checkpoint. Errors are one line.
    fn restore(&mut self, state: Self::State, dir: &Path, at: Resumed) -> Result<(), EngineError>;
}

/// Cuts an output file back to `bytes` (its length at a checkpoint) and opens it for appending, so that a resumed
/// run continues it exactly. Errors are one line naming the file (missing, or shorter than at the checkpoint).
pub fn reopen_truncated(path: &Path, bytes: u64) -> Result<std::fs::File, EngineError> {
    let file_err = |reason: String| EngineError::File {
        path: path.to_path_buf(),
        reason,
    };
    let err = |e: std::io::Error| file_err(crate::io::safe_write::reason(&e));
    // Never through a link (crate::io::safe_write): the file opened is the regular file at `path`.
    let mut file = crate::io::safe_write::open_nofollow(path, false).map_err(err)?;
    let len = file.metadata().map_err(err)?.len();
    if len < bytes {
        return Err(file_err(format!(
            "holds {len} bytes, fewer than the {bytes} written before the checkpoint"
        )));
    }
    file.set_len(bytes).map_err(err)?;
    std::io::Seek::seek(&mut file, std::io::SeekFrom::End(0)).map_err(err)?;
    Ok(file)
}
