//! The Python front of rubblepile: the extension module `rubblepile._rubblepile`, re-exported by the Python package
//! `rubblepile` (`python/rubblepile/__init__.py`).
//!
//! A [`Simulation`] holds one run in memory ([`rubblepile::driver::Session`]): the same driver as the command
//! line's `rubblepile run`, advanced output sample by output sample, writing the same run directory as it goes, so
//! that a scene run here and by the command line gives the same files. Errors are Python exceptions carrying the
//! command line's one-line message.

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use rubblepile::driver::{RunError, RunOptions, SceneKind, Session, Step};
use rubblepile::ellipsoid::run::EllipsoidEngine;
use rubblepile::engine::{Engine, EngineError, ParticleView};
use rubblepile::granular::hard::run::HardEngine;
use rubblepile::granular::soft::run::SoftEngine;

create_exception!(
    _rubblepile,
    RubblepileError,
    PyException,
    "Any error of rubblepile; the message is the command line's one line."
);
create_exception!(
    _rubblepile,
    SceneError,
    RubblepileError,
    "The scene, an argument or a run directory cannot be used (the command line's exit code 2); the message names \
     the field."
);
create_exception!(
    _rubblepile,
    RunFailed,
    RubblepileError,
    "The run failed (non-finite state, step-size underflow, …): `t` is the last good time (s), `summary` the \
     summary written, `last_good_state` its file."
);
create_exception!(
    _rubblepile,
    RunStopped,
    RubblepileError,
    "The run stopped with a checkpoint (its step or wall-clock budget ran out): `t` is the checkpoint's time (s); \
     continue it with `Simulation.from_run(dir)`."
);

/// A run error, without the GIL: what a [`RunError`] of any engine becomes, turned into an exception later.
struct Failure {
    message: String,
    class: Class,
    t: Option<f64>,
    summary: Option<String>,
    last_good_state: Option<PathBuf>,
}

#[derive(Clone, Copy)]
enum Class {
    Scene,
    Failed,
    Stopped,
    Other,
}

impl<S: serde::Serialize> From<RunError<S>> for Failure {
    fn from(e: RunError<S>) -> Self {
        let message = e.to_string();
        let class = if e.is_usage() { Class::Scene } else { Class::Other };
        let mut f = Failure {
            message,
            class,
            t: None,
            summary: None,
            last_good_state: None,
        };
        match e {
            RunError::Failed {
                t,
                summary,
                last_good_state,
                ..
            } => {
                f.class = Class::Failed;
                f.t = Some(t);
                f.summary = serde_json::to_string(&summary).ok();
                f.last_good_state = Some(last_good_state);
            }
            RunError::Budget { t, .. } | RunError::Stopped { t, .. } => {
                f.class = Class::Stopped;
                f.t = Some(t);
            }
            _ => {}
        }
        f
    }
}

impl From<EngineError> for Failure {
    fn from(e: EngineError) -> Self {
        Failure::scene(e.to_string())
    }
}

impl Failure {
    fn scene(message: String) -> Self {
        Failure {
            message,
            class: Class::Scene,
            t: None,
            summary: None,
            last_good_state: None,
        }
    }

    fn into_py(self, py: Python<'_>) -> PyErr {
        let err = match self.class {
            Class::Scene => SceneError::new_err(self.message),
            Class::Failed => RunFailed::new_err(self.message),
            Class::Stopped => RunStopped::new_err(self.message),
            Class::Other => RubblepileError::new_err(self.message),
        };
        let value = err.value(py);
        let summary = self.summary.and_then(|s| json_loads(py, &s).ok());
        // Attributes of the exception object; a failure to set one leaves the message intact.
        let _ = value.setattr("t", self.t);
        let _ = value.setattr("summary", summary);
        let _ = value.setattr("last_good_state", self.last_good_state.map(|p| p.display().to_string()));
        err
    }
}

fn json_loads<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (text,))
}

/// One run of any engine.
enum Any {
    Ellipsoids(Session<EllipsoidEngine>),
    SoftSpheres(Session<SoftEngine>),
    HardSpheres(Session<HardEngine>),
}

/// `$body` with `$s` bound to the session of whichever engine `$any` runs.
macro_rules! each {
    ($any:expr, $s:ident => $body:expr) => {
        match $any {
            Any::Ellipsoids($s) => $body,
            Any::SoftSpheres($s) => $body,
            Any::HardSpheres($s) => $body,
        }
    };
}

/// How [`Any::advance`] ended.
enum Advanced {
    /// The target was reached (or the run completed).
    Reached,
    /// The chunk's wall-clock time ran out first.
    Chunk,
}

/// Steps `s` while its next sample is at or before `target` (s) and `chunk` has not passed.
fn advance<E: Engine>(s: &mut Session<E>, target: f64, chunk: Duration) -> Result<Advanced, Failure>
where
    E::Summary: serde::Serialize,
{
    let started = Instant::now();
    s.on_pool(|s| {
        loop {
            let due = s.samples().get(s.next_sample()).is_some_and(|x| x.t <= target);
            if s.is_done() || !due {
                return Ok(Advanced::Reached);
            }
            if let Step::Completed(_) = s.step()? {
                return Ok(Advanced::Reached);
            }
            if started.elapsed() >= chunk {
                return Ok(Advanced::Chunk);
            }
        }
    })
}

/// The time of the next sample at or before `target + tolerance` (s), for grids built by repeated addition.
fn target_with_slack(target: f64) -> f64 {
    target + 1e-9 * target.abs().max(1e-9)
}

impl Any {
    fn kind(&self) -> SceneKind {
        match self {
            Any::Ellipsoids(_) => SceneKind::Ellipsoids,
            Any::SoftSpheres(_) => SceneKind::SoftSpheres,
            Any::HardSpheres(_) => SceneKind::HardSpheres,
        }
    }

    fn advance(&mut self, target: f64, chunk: Duration) -> Result<Advanced, Failure> {
        each!(self, s => advance(s, target, chunk))
    }

    fn step(&mut self) -> Result<(), Failure> {
        each!(self, s => s.on_pool(|s| s.step().map(|_| ()).map_err(Failure::from)))
    }

    fn time(&self) -> f64 {
        each!(self, s => s.engine().time())
    }

    fn t_end(&self) -> f64 {
        each!(self, s => s.engine().t_end())
    }

    fn is_done(&self) -> bool {
        each!(self, s => s.is_done())
    }

    fn sample_times(&self) -> Vec<f64> {
        each!(self, s => s.samples().iter().map(|x| x.t).collect())
    }

    fn next_sample(&self) -> usize {
        each!(self, s => s.next_sample())
    }

    fn checkpoint(&mut self) -> Result<(), Failure> {
        each!(self, s => s.checkpoint().map_err(Failure::from))
    }

    fn summary_json(&self) -> String {
        each!(self, s => serde_json::to_string(&s.summary()).unwrap_or_else(|_| "{}".into()))
    }

    fn wall_seconds(&self) -> f64 {
        each!(self, s => s.wall_seconds())
    }

    fn particles(&self) -> Vec<ParticleView> {
        each!(self, s => s.engine().particles())
    }

    fn warnings(&self) -> Vec<String> {
        match self {
            Any::Ellipsoids(s) => s.engine().scene_warnings().to_vec(),
            Any::SoftSpheres(s) => s.engine().scene_warnings().to_vec(),
            Any::HardSpheres(s) => s.engine().scene_warnings().to_vec(),
        }
    }
}

/// Run options of the Python calls, as the command line's `--checkpoint-every-s`, `--max-steps`, ….
fn options(
    force: bool,
    checkpoint_every: Option<f64>,
    checkpoint_every_sim: Option<f64>,
    max_steps: Option<u64>,
    max_wall_seconds: Option<f64>,
) -> RunOptions {
    RunOptions {
        force,
        progress: false,
        checkpoint_every: checkpoint_every.or(RunOptions::default().checkpoint_every),
        checkpoint_every_sim,
        max_steps,
        max_wall_seconds,
        ..RunOptions::default()
    }
}

/// A fresh directory under the system's temporary directory for a run given no output directory.
fn temporary_dir() -> PathBuf {
    static COUNT: AtomicU64 = AtomicU64::new(0);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.subsec_nanos());
    std::env::temp_dir().join(format!(
        "rubblepile-py-{}-{}-{nanos}",
        std::process::id(),
        COUNT.fetch_add(1, Ordering::Relaxed)
    ))
}

/// Where a scene comes from.
enum Source {
    File(PathBuf),
    Text(String),
}

/// The scene argument of [`Simulation::from_scene`]: a path (`str` or `os.PathLike`) of an existing file, a `dict`
/// (written as TOML), or TOML text.
fn source_of(scene: &Bound<'_, PyAny>) -> PyResult<Source> {
    let py = scene.py();
    if let Ok(d) = scene.cast::<PyDict>() {
        let json: String = py.import("json")?.call_method1("dumps", (d,))?.extract()?;
        let value: toml::Value = serde_json::from_str(&json)
            .map_err(|e| SceneError::new_err(format!("scene dict: not a TOML table: {e}")))?;
        let text =
            toml::to_string(&value).map_err(|e| SceneError::new_err(format!("scene dict: not a TOML table: {e}")))?;
        return Ok(Source::Text(text));
    }
    if let Ok(s) = scene.cast::<PyString>() {
        let s: String = s.extract()?;
        if s.contains('\n') || s.contains('[') || s.contains('=') {
            return Ok(Source::Text(s));
        }
        return Ok(Source::File(PathBuf::from(s)));
    }
    let path: PathBuf = scene
        .extract()
        .map_err(|_| PyValueError::new_err("scene: expected a path, a dict or TOML text"))?;
    Ok(Source::File(path))
}

fn start<E: Engine>(engine: E, out: &Path, options: &RunOptions) -> Result<Session<E>, Failure>
where
    E::Summary: serde::Serialize,
{
    Session::start(engine, out, options).map_err(Failure::from)
}

/// Loads the scene and starts its run in `out`.
fn start_any(source: &Source, out: &Path, options: &RunOptions) -> Result<Any, Failure> {
    let (kind, base) = match source {
        Source::File(p) => (SceneKind::of_file(p), p.parent().map(Path::to_path_buf)),
        Source::Text(t) => (SceneKind::of_text(t), None),
    };
    let name = "scene";
    Ok(match (kind, source) {
        (SceneKind::Ellipsoids, Source::File(p)) => Any::Ellipsoids(start(EllipsoidEngine::load(p)?, out, options)?),
        (SceneKind::SoftSpheres, Source::File(p)) => Any::SoftSpheres(start(SoftEngine::load(p)?, out, options)?),
        (SceneKind::HardSpheres, Source::File(p)) => Any::HardSpheres(start(HardEngine::load(p)?, out, options)?),
        (SceneKind::Ellipsoids, Source::Text(t)) => Any::Ellipsoids(start(
            EllipsoidEngine::from_scene_text(t, name, base.as_deref())?,
            out,
            options,
        )?),
        (SceneKind::SoftSpheres, Source::Text(t)) => Any::SoftSpheres(start(
            SoftEngine::from_scene_text(t, name, base.as_deref())?,
            out,
            options,
        )?),
        (SceneKind::HardSpheres, Source::Text(t)) => Any::HardSpheres(start(
            HardEngine::from_scene_text(t, name, base.as_deref())?,
            out,
            options,
        )?),
    })
}

fn resume_any(dir: &Path, options: &RunOptions) -> Result<Any, Failure> {
    Ok(match SceneKind::of_run_dir(dir) {
        SceneKind::Ellipsoids => Any::Ellipsoids(Session::resume(dir, options)?),
        SceneKind::SoftSpheres => Any::SoftSpheres(Session::resume(dir, options)?),
        SceneKind::HardSpheres => Any::HardSpheres(Session::resume(dir, options)?),
    })
}

/// Copies the run directory `from` into `to` (created; refused when it holds files unless `force`), lock files
/// left out.
fn copy_run(from: &Path, to: &Path, force: bool) -> Result<(), Failure> {
    let io = |p: &Path, e: std::io::Error| Failure {
        class: Class::Other,
        ..Failure::scene(format!("{}: {e}", p.display()))
    };
    if to.exists() {
        if !to.is_dir() {
            return Err(Failure::scene(format!(
                "output path {} exists and is not a directory",
                to.display()
            )));
        }
        let busy = std::fs::read_dir(to).map_err(|e| io(to, e))?.next().is_some();
        if busy && !force {
            return Err(Failure::scene(format!(
                "output directory {} exists and is not empty; use force=True to overwrite it",
                to.display()
            )));
        }
    }
    fn walk(from: &Path, to: &Path, io: &dyn Fn(&Path, std::io::Error) -> Failure) -> Result<(), Failure> {
        std::fs::create_dir_all(to).map_err(|e| io(to, e))?;
        for entry in std::fs::read_dir(from).map_err(|e| io(from, e))? {
            let entry = entry.map_err(|e| io(from, e))?;
            let p = entry.path();
            let name = entry.file_name();
            if rubblepile::io::run_lock::is_lock_file(&name) {
                continue;
            }
            let target = to.join(&name);
            if p.is_dir() {
                walk(&p, &target, io)?;
            } else {
                std::fs::copy(&p, &target).map_err(|e| io(&p, e))?;
            }
        }
        Ok(())
    }
    walk(from, to, &io)
}

/// Seconds of simulated work between two looks for Ctrl-C (the GIL is released meanwhile).
const CHUNK: Duration = Duration::from_millis(200);

/// One simulation of any engine, held in memory, writing its run directory as it advances (see the Python
/// docstrings in `python/rubblepile/_rubblepile.pyi`).
#[pyclass(module = "rubblepile")]
struct Simulation {
    run: Mutex<Option<Any>>,
    out_dir: PathBuf,
    temporary: bool,
}

impl Simulation {
    fn with<R>(&self, f: impl FnOnce(&mut Any) -> Result<R, Failure>) -> Result<R, Failure> {
        let mut guard = self.run.lock().unwrap_or_else(|e| e.into_inner());
        match guard.as_mut() {
            Some(any) => f(any),
            None => Err(Failure::scene(format!(
                "the simulation writing {} was closed",
                self.out_dir.display()
            ))),
        }
    }

    fn read<R>(&self, py: Python<'_>, f: impl FnOnce(&mut Any) -> Result<R, Failure>) -> PyResult<R> {
        self.with(f).map_err(|e| e.into_py(py))
    }

    fn new(py: Python<'_>, any: Any, out_dir: PathBuf, temporary: bool) -> PyResult<Self> {
        let warnings = py.import("warnings")?;
        for w in any.warnings() {
            warnings.call_method1("warn", (w,))?;
        }
        Ok(Simulation {
            run: Mutex::new(Some(any)),
            out_dir,
            temporary,
        })
    }

    /// Advances to `target` (s) in chunks, the GIL released, looking for Ctrl-C between chunks: on an interrupt,
    /// a checkpoint is written (when the run is between two samples) before the exception is raised.
    fn advance_to(&self, py: Python<'_>, target: f64) -> PyResult<f64> {
        loop {
            let reached = py.detach(|| self.with(|any| any.advance(target, CHUNK)));
            match reached.map_err(|e| e.into_py(py))? {
                Advanced::Reached => break,
                Advanced::Chunk => {}
            }
            if let Err(interrupt) = py.check_signals() {
                // The checkpoint is refused only before the first sample and after the last: nothing to keep then.
                let _ = self.with(|any| any.checkpoint());
                return Err(interrupt);
            }
        }
        self.read(py, |any| Ok(any.time()))
    }
}

fn array3(rows: impl Iterator<Item = [f64; 3]>) -> Array2<f64> {
    let flat: Vec<f64> = rows.flatten().collect();
    let n = flat.len() / 3;
    Array2::from_shape_vec((n, 3), flat).expect("three columns")
}

/// Positions, velocities and world-frame spins (`angular_velocities`) of a sphere run: those of `now` with the
/// arrays given (one row per sphere) in their place.
fn sphere_state(
    now: &[ParticleView],
    arrays: &[(String, Array2<f64>)],
) -> Result<[Vec<rubblepile::math::Vec3>; 3], Failure> {
    use rubblepile::math::Vec3;
    const WRITABLE: [&str; 3] = ["positions", "velocities", "angular_velocities"];
    let n = now.len();
    let mut columns: [Vec<Vec3>; 3] = [
        now.iter().map(|p| p.position).collect(),
        now.iter().map(|p| p.velocity).collect(),
        now.iter().map(|p| p.spin_world).collect(),
    ];
    for (name, a) in arrays {
        let Some(k) = WRITABLE.iter().position(|w| w == name) else {
            return Err(Failure::scene(format!(
                "{name}: not a writable state array of a sphere run ({})",
                WRITABLE.join(", ")
            )));
        };
        if a.dim() != (n, 3) {
            return Err(Failure::scene(format!(
                "{name}: expected shape ({n}, 3), got {:?}",
                a.dim()
            )));
        }
        columns[k] = a.rows().into_iter().map(|r| Vec3::new(r[0], r[1], r[2])).collect();
    }
    Ok(columns)
}

#[pymethods]
impl Simulation {
    /// See `rubblepile.Simulation.from_scene`.
    #[staticmethod]
    #[pyo3(signature = (scene, out=None, *, force=false, checkpoint_every=None, checkpoint_every_sim=None, max_steps=None, max_wall_seconds=None))]
    #[allow(clippy::too_many_arguments)]
    fn from_scene(
        py: Python<'_>,
        scene: &Bound<'_, PyAny>,
        out: Option<PathBuf>,
        force: bool,
        checkpoint_every: Option<f64>,
        checkpoint_every_sim: Option<f64>,
        max_steps: Option<u64>,
        max_wall_seconds: Option<f64>,
    ) -> PyResult<Self> {
        let source = source_of(scene)?;
        let options = options(
            force,
            checkpoint_every,
            checkpoint_every_sim,
            max_steps,
            max_wall_seconds,
        );
        let temporary = out.is_none();
        let out = out.unwrap_or_else(temporary_dir);
        let any = py
            .detach(|| start_any(&source, &out, &options))
            .map_err(|e| e.into_py(py))?;
        Simulation::new(py, any, out, temporary)
    }

    /// See `rubblepile.Simulation.from_run`.
    #[staticmethod]
    #[pyo3(signature = (dir, *, checkpoint_every=None, checkpoint_every_sim=None, max_steps=None, max_wall_seconds=None))]
    fn from_run(
        py: Python<'_>,
        dir: PathBuf,
        checkpoint_every: Option<f64>,
        checkpoint_every_sim: Option<f64>,
        max_steps: Option<u64>,
        max_wall_seconds: Option<f64>,
    ) -> PyResult<Self> {
        let options = options(
            false,
            checkpoint_every,
            checkpoint_every_sim,
            max_steps,
            max_wall_seconds,
        );
        let any = py.detach(|| resume_any(&dir, &options)).map_err(|e| e.into_py(py))?;
        Simulation::new(py, any, dir, false)
    }

    /// See `rubblepile.Simulation.integrate`.
    #[pyo3(signature = (t=None))]
    fn integrate(&self, py: Python<'_>, t: Option<f64>) -> PyResult<f64> {
        let t_end = self.read(py, |any| Ok(any.t_end()))?;
        let target = match t {
            None => t_end,
            Some(t) if !t.is_finite() => return Err(PyValueError::new_err(format!("t = {t} s is not finite"))),
            Some(t) if t > target_with_slack(t_end) => {
                return Err(PyValueError::new_err(format!(
                    "t = {t} s is past the scene's t_end = {t_end} s (scene.t_end)"
                )));
            }
            Some(t) => t,
        };
        self.advance_to(py, target_with_slack(target))
    }

    /// See `rubblepile.Simulation.step`.
    fn step(&self, py: Python<'_>) -> PyResult<f64> {
        py.detach(|| self.with(|any| any.step())).map_err(|e| e.into_py(py))?;
        self.read(py, |any| Ok(any.time()))
    }

    /// See `rubblepile.Simulation.checkpoint`.
    fn checkpoint(&self, py: Python<'_>) -> PyResult<()> {
        py.detach(|| self.with(|any| any.checkpoint()))
            .map_err(|e| e.into_py(py))
    }

    /// See `rubblepile.Simulation.save`.
    #[pyo3(signature = (dir, *, force=false))]
    fn save(&self, py: Python<'_>, dir: PathBuf, force: bool) -> PyResult<()> {
        let out = self.out_dir.clone();
        py.detach(|| {
            self.with(|any| {
                if !any.is_done() && any.next_sample() > 0 {
                    any.checkpoint()?;
                }
                let same = match (std::fs::canonicalize(&out), std::fs::canonicalize(&dir)) {
                    (Ok(a), Ok(b)) => a == b,
                    _ => false,
                };
                if same { Ok(()) } else { copy_run(&out, &dir, force) }
            })
        })
        .map_err(|e| e.into_py(py))
    }

    /// See `rubblepile.Simulation.close`.
    fn close(&self) {
        let mut guard = self.run.lock().unwrap_or_else(|e| e.into_inner());
        guard.take();
    }

    /// Simulated time now (s).
    #[getter]
    fn t(&self, py: Python<'_>) -> PyResult<f64> {
        self.read(py, |any| Ok(any.time()))
    }

    /// The scene's end time (s).
    #[getter]
    fn t_end(&self, py: Python<'_>) -> PyResult<f64> {
        self.read(py, |any| Ok(any.t_end()))
    }

    /// Whether the run has ended (completed, failed or stopped by its budget): nothing more to advance.
    #[getter]
    fn done(&self, py: Python<'_>) -> PyResult<bool> {
        self.read(py, |any| Ok(any.is_done()))
    }

    /// The engine: "ellipsoids", "soft-spheres" or "hard-spheres".
    #[getter]
    fn kind(&self, py: Python<'_>) -> PyResult<String> {
        self.read(py, |any| Ok(any.kind().to_string()))
    }

    /// The run directory being written.
    #[getter]
    fn out_dir(&self) -> String {
        self.out_dir.display().to_string()
    }

    /// Whether the run directory is a temporary one (no `out` given).
    #[getter]
    fn temporary(&self) -> bool {
        self.temporary
    }

    /// Times of every output sample (s).
    #[getter]
    fn sample_times<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let v = self.read(py, |any| Ok(any.sample_times()))?;
        Ok(Array1::from(v).into_pyarray(py))
    }

    /// Output samples reached so far.
    #[getter]
    fn samples_done(&self, py: Python<'_>) -> PyResult<usize> {
        self.read(py, |any| Ok(any.next_sample()))
    }

    /// Wall-clock seconds of the run so far.
    #[getter]
    fn wall_seconds(&self, py: Python<'_>) -> PyResult<f64> {
        self.read(py, |any| Ok(any.wall_seconds()))
    }

    /// The summary as `summary.json` would hold it now (JSON text).
    fn _summary_json(&self, py: Python<'_>) -> PyResult<String> {
        self.read(py, |any| Ok(any.summary_json()))
    }

    /// The particles now: a dict of arrays (see `rubblepile.Simulation.state`).
    fn _state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (particles, bodies) = self.read(py, |any| {
            let bodies = match any {
                Any::Ellipsoids(s) => Some(s.engine().bodies()),
                _ => None,
            };
            Ok((any.particles(), bodies))
        })?;
        let d = PyDict::new(py);
        let ids: Array1<i64> = particles.iter().map(|p| p.id as i64).collect();
        let masses: Array1<f64> = particles.iter().map(|p| p.mass).collect();
        d.set_item("ids", ids.into_pyarray(py))?;
        d.set_item("masses", masses.into_pyarray(py))?;
        d.set_item(
            "positions",
            array3(particles.iter().map(|p| p.position.into())).into_pyarray(py),
        )?;
        d.set_item(
            "velocities",
            array3(particles.iter().map(|p| p.velocity.into())).into_pyarray(py),
        )?;
        d.set_item(
            "angular_velocities",
            array3(particles.iter().map(|p| p.spin_world.into())).into_pyarray(py),
        )?;
        match bodies {
            Some(bodies) => {
                let q: Vec<f64> = bodies.iter().flat_map(|b| <[f64; 4]>::from(b.quaternion)).collect();
                let n = bodies.len();
                d.set_item(
                    "quaternions",
                    Array2::from_shape_vec((n, 4), q)
                        .expect("four columns")
                        .into_pyarray(py),
                )?;
                d.set_item(
                    "spins_body",
                    array3(bodies.iter().map(|b| b.spin_body.into())).into_pyarray(py),
                )?;
                d.set_item(
                    "semi_axes",
                    array3(particles.iter().map(|p| p.axes.into())).into_pyarray(py),
                )?;
            }
            None => {
                let radii: Array1<f64> = particles.iter().map(|p| p.axes.x).collect();
                d.set_item("radii", radii.into_pyarray(py))?;
            }
        }
        Ok(d)
    }

    /// Sets the state of an ellipsoid run between samples (see `rubblepile.Simulation.set_state`): `state` maps
    /// `positions`, `velocities`, `angular_velocities` (world frame) or `spins_body`, `quaternions` to float64
    /// arrays of one row per body.
    fn _set_state(&self, py: Python<'_>, state: &Bound<'_, PyDict>) -> PyResult<()> {
        let mut arrays: Vec<(String, Array2<f64>)> = Vec::new();
        for (k, v) in state.iter() {
            let name: String = k.extract()?;
            let a: numpy::PyReadonlyArray2<'_, f64> = v
                .extract()
                .map_err(|_| PyValueError::new_err(format!("{name}: expected a 2-D float64 array")))?;
            arrays.push((name, a.as_array().to_owned()));
        }
        self.read(py, |any| {
            let s = match any {
                Any::SoftSpheres(s) => {
                    let [x, v, w] = sphere_state(&s.engine().particles(), &arrays)?;
                    return s.engine_mut().set_particles(&x, &v, &w).map_err(Failure::from);
                }
                Any::HardSpheres(s) => {
                    let [x, v, w] = sphere_state(&s.engine().particles(), &arrays)?;
                    return s.engine_mut().set_particles(&x, &v, &w).map_err(Failure::from);
                }
                Any::Ellipsoids(s) => s,
            };
            let mut bodies = s.engine().bodies();
            let n = bodies.len();
            let mut world_spin: Option<Array2<f64>> = None;
            const WRITABLE: [&str; 5] = [
                "positions",
                "velocities",
                "quaternions",
                "angular_velocities",
                "spins_body",
            ];
            if let Some((other, _)) = arrays.iter().find(|(k, _)| !WRITABLE.contains(&k.as_str())) {
                return Err(Failure::scene(format!(
                    "{other}: not a writable state array ({})",
                    WRITABLE.join(", ")
                )));
            }
            for (name, a) in &arrays {
                let width = if name == "quaternions" { 4 } else { 3 };
                if a.dim() != (n, width) {
                    return Err(Failure::scene(format!(
                        "{name}: expected shape ({n}, {width}), got {:?}",
                        a.dim()
                    )));
                }
                for (i, b) in bodies.iter_mut().enumerate() {
                    let r = a.row(i);
                    let v3 = rubblepile::math::Vec3::new(r[0], r[1], r[2]);
                    match name.as_str() {
                        "positions" => b.position = v3,
                        "velocities" => b.velocity = v3,
                        "spins_body" => b.spin_body = v3,
                        "quaternions" => b.quaternion = rubblepile::math::Vec4::new(r[0], r[1], r[2], r[3]),
                        _ => {}
                    }
                }
                if name == "angular_velocities" {
                    world_spin = Some(a.clone());
                }
            }
            if let Some(w) = world_spin {
                if arrays.iter().any(|(k, _)| k == "spins_body") {
                    return Err(Failure::scene(
                        "angular_velocities, spins_body: give one of the two spins, not both".into(),
                    ));
                }
                for (i, b) in bodies.iter_mut().enumerate() {
                    let r = w.row(i);
                    let q = b.quaternion.normalize();
                    b.spin_body = rubblepile::ellipsoid::quaternion::rotation_matrix(&q)
                        * rubblepile::math::Vec3::new(r[0], r[1], r[2]);
                }
            }
            s.engine_mut().set_bodies(&bodies).map_err(Failure::from)
        })
    }

    fn __enter__(slf: Py<Self>) -> Py<Self> {
        slf
    }

    #[pyo3(signature = (*_args))]
    fn __exit__(&self, _args: &Bound<'_, pyo3::types::PyTuple>) {
        self.close();
    }
}

impl Drop for Simulation {
    fn drop(&mut self) {
        let run = self.run.get_mut().unwrap_or_else(|e| e.into_inner());
        run.take();
        if self.temporary {
            // A temporary run directory nobody can name any more.
            let _ = std::fs::remove_dir_all(&self.out_dir);
        }
    }
}

/// An impact error as a Python exception: a bad value names the keyword argument, like the command line its flag.
fn impact_failure(e: rubblepile::impact::error::ImpactError) -> Failure {
    use rubblepile::impact::error::ImpactError;
    match e {
        ImpactError::Run(r) => Failure::from(r),
        ImpactError::Invalid { field, message } => {
            let arg = match field.as_str() {
                "projectile.speed" => "speed".to_string(),
                f if f.starts_with("projectile") => "projectile_radius".to_string(),
                f => f.to_string(),
            };
            Failure::scene(format!("{arg}: {message}"))
        }
        ImpactError::Target { path, message } => Failure::scene(format!("target {}: {message}", path.display())),
        other => {
            let scene = matches!(other, ImpactError::Scene(_));
            let mut f = Failure::scene(other.to_string());
            if !scene {
                f.class = Class::Other;
            }
            f
        }
    }
}

/// `rubblepile.impact`: prepares the impact's run directory as `rubblepile impact` does and returns its
/// simulation, not yet advanced (see the Python docstring).
#[pyfunction]
#[pyo3(signature = (target, out=None, *, projectile="P2", projectile_radius=None, speed=5000.0, angle=45.0, seed=1, contact_time=90.0, t_end=10000.0, rtol=None, method="bulirsch-stoer", f0=rubblepile::impact::run::DEFAULT_F0, beta=10.0, inertia="gaussian", kappa_reading="printed", snapshots=None, snapshot_every=None, every=10.0, force=false, checkpoint_every=None, checkpoint_every_sim=None, impact_parameter_m=None, impact_parameter_frac=None, impact_angle_deg=None, aim_azimuth_deg=None, projectile_spin_rad_s=None, projectile_attitude=None))]
#[allow(clippy::too_many_arguments)]
fn impact(
    py: Python<'_>,
    target: PathBuf,
    out: Option<PathBuf>,
    projectile: &str,
    projectile_radius: Option<f64>,
    speed: f64,
    angle: f64,
    seed: u64,
    contact_time: f64,
    t_end: f64,
    rtol: Option<f64>,
    method: &str,
    f0: f64,
    beta: f64,
    inertia: &str,
    kappa_reading: &str,
    snapshots: Option<Vec<f64>>,
    snapshot_every: Option<f64>,
    every: f64,
    force: bool,
    checkpoint_every: Option<f64>,
    checkpoint_every_sim: Option<f64>,
    impact_parameter_m: Option<f64>,
    impact_parameter_frac: Option<f64>,
    impact_angle_deg: Option<f64>,
    aim_azimuth_deg: Option<f64>,
    projectile_spin_rad_s: Option<Vec<f64>>,
    projectile_attitude: Option<Vec<f64>>,
) -> PyResult<Simulation> {
    use rubblepile::impact::projectile::ProjectileSpec;
    use rubblepile::impact::run::{ImpactConfig, default_rtol, prepare_impact, snapshot_times};
    use rubblepile::named::Named;
    let usage = |m: String| Failure::scene(m).into_py(py);
    let spec = match projectile_radius {
        Some(r) if r > 0.0 && r.is_finite() => ProjectileSpec::custom("custom".into(), r, speed),
        Some(r) => return Err(usage(format!("projectile_radius: must be > 0 m, got {r}"))),
        None => {
            let mut p = ProjectileSpec::preset(projectile)
                .ok_or_else(|| usage(format!("projectile: expected P1, P2 or P3, got {projectile}")))?;
            p.speed = speed;
            p
        }
    };
    let method = rubblepile::integrate::Method::from_name(method).ok_or_else(|| {
        usage(format!(
            "method: expected one of {}, got {method}",
            rubblepile::integrate::Method::ALL
                .iter()
                .map(|m| m.name())
                .collect::<Vec<_>>()
                .join(", ")
        ))
    })?;
    let inertia = match inertia {
        "gaussian" => rubblepile::ellipsoid::body::InertiaModel::Gaussian,
        "uniform" => rubblepile::ellipsoid::body::InertiaModel::Uniform,
        other => return Err(usage(format!("inertia: expected gaussian or uniform, got {other}"))),
    };
    let kappa_reading = kappa_reading
        .parse()
        .map_err(|e: String| usage(format!("kappa_reading: {e}")))?;
    let snapshots =
        snapshot_times(t_end, snapshots.as_deref(), snapshot_every).map_err(|m| usage(format!("snapshots: {m}")))?;
    let geometry = rubblepile::impact::geometry::ImpactGeometry::from_options(
        [impact_parameter_m, impact_parameter_frac, impact_angle_deg],
        aim_azimuth_deg,
        projectile_spin_rad_s.as_deref(),
        projectile_attitude.as_deref(),
    )
    .map_err(|e| impact_failure(e).into_py(py))?;
    let cfg = ImpactConfig {
        geometry,
        angle_deg: angle,
        seed,
        contact_time,
        t_end,
        method,
        rtol: rtol.unwrap_or(default_rtol(method)),
        f0,
        beta,
        kappa_reading,
        snapshots,
        every,
        inertia,
        ..ImpactConfig::new(target, spec)
    };
    let options = RunOptions {
        force: true,
        ..options(force, checkpoint_every, checkpoint_every_sim, None, None)
    };
    let temporary = out.is_none();
    let out = out.unwrap_or_else(temporary_dir);
    let any = py
        .detach(|| {
            let prepared = prepare_impact(&cfg, &out, force).map_err(impact_failure)?;
            let engine = EllipsoidEngine::new(prepared.scene).map_err(Failure::from)?;
            let session = Session::start(engine, &out, &options).map_err(Failure::from)?;
            // The session holds the directory's lock now (re-entrant on this thread).
            drop(prepared.lock);
            Ok::<_, Failure>(Any::Ellipsoids(session))
        })
        .map_err(|e| e.into_py(py))?;
    Simulation::new(py, any, out, temporary)
}

/// `rubblepile.analyze`: what `rubblepile analyze DIR [--at-s T]` computes and writes (`DIR/analysis/`), as JSON
/// text of `analysis.json` with the CLI's summary lines (see the Python docstring).
#[pyfunction]
#[pyo3(signature = (dir, at=None, *, force=false))]
fn analyze(py: Python<'_>, dir: PathBuf, at: Option<f64>, force: bool) -> PyResult<(String, Vec<String>)> {
    use rubblepile::analysis::run_analysis::{analyze_clumps_run, analyze_run, is_impact_run, lock_analysis};
    let usage = |m: String| Failure::scene(m);
    let result = py.detach(|| {
        let _lock = lock_analysis(&dir, "scene.toml").map_err(|e| usage(e.to_string()))?;
        if let Some(at) = at
            && !(at.is_finite() && at >= 0.0)
        {
            return Err(usage(format!("at: must be a time >= 0 s, got {at}")));
        }
        if !is_impact_run(&dir) {
            let a = analyze_clumps_run(&dir, None, at, force).map_err(|e| usage(e.to_string()))?;
            let line = a.write_figure_and_describe(&dir.join("analysis"));
            let json = serde_json::to_string(&a).map_err(|e| usage(e.to_string()))?;
            return Ok((json, vec![line]));
        }
        if at == Some(0.0) {
            return Err(usage(
                "at: an impact run is analysed after the impact: must be a time > 0 s, got 0".into(),
            ));
        }
        let at = rubblepile::analysis::run_analysis::analysis_time(&dir, at).map_err(|e| usage(e.to_string()))?;
        let (a, report) = analyze_run(&dir, None, at, force).map_err(|e| usage(e.to_string()))?;
        let (_figures, not_drawn) = rubblepile::analysis::figures::write_run_figures(&dir, None, &a, &report);
        let mut lines = vec![a.clump_lines()];
        if let Some(c) = &a.composition {
            lines.push(c.summary_line());
        }
        lines.extend(not_drawn.iter().map(|w| format!("warning: figure not drawn: {w}")));
        let json = serde_json::to_string(&a).map_err(|e| usage(e.to_string()))?;
        Ok((json, lines))
    });
    result.map_err(|e| e.into_py(py))
}

/// `rubblepile.build_target`: `rubblepile target build` (see the Python docstring); returns the report JSON text.
#[pyfunction]
#[pyo3(signature = (fragments, period_hours, out, *, seed=1, r_largest_km=None, r_smallest_km=None, total_mass=None, f0=None, rigidity=1e-4, drop_detached=false, kappa_reading="printed", force=false))]
#[allow(clippy::too_many_arguments)]
fn build_target(
    py: Python<'_>,
    fragments: usize,
    period_hours: f64,
    out: PathBuf,
    seed: u64,
    r_largest_km: Option<f64>,
    r_smallest_km: Option<f64>,
    total_mass: Option<f64>,
    f0: Option<f64>,
    rigidity: f64,
    drop_detached: bool,
    kappa_reading: &str,
    force: bool,
) -> PyResult<String> {
    use rubblepile::impact::target::{TargetSpec, build_target};
    let usage = |m: String| Failure::scene(m);
    let result = py.detach(|| {
        let mut spec =
            TargetSpec::table1_or_sizes(fragments, period_hours, seed, r_largest_km, r_smallest_km).map_err(usage)?;
        if let Some(m) = total_mass {
            spec.total_mass = m;
        }
        if let Some(f0) = f0 {
            spec.f0 = f0;
        }
        if !(rigidity > 0.0 && rigidity < 1.0) {
            return Err(usage(format!(
                "rigidity: expected a fraction in (0, 1), got {rigidity}"
            )));
        }
        spec.rigidity = rigidity;
        spec.drop_detached = drop_detached;
        spec.kappa_reading = kappa_reading
            .parse()
            .map_err(|e: String| usage(format!("kappa_reading: {e}")))?;
        if out.extension().is_none_or(|e| e != "csv") {
            return Err(usage(format!(
                "out: expected a path ending in .csv, got {}",
                out.display()
            )));
        }
        let json = out.with_extension("json");
        if !force && (out.exists() || json.exists()) {
            return Err(usage(format!(
                "out: {} (or its .json) exists; use force=True to overwrite it",
                out.display()
            )));
        }
        let failed = |m: String| Failure {
            class: Class::Other,
            ..Failure::scene(m)
        };
        if let Some(dir) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| failed(format!("{}: {e}", dir.display())))?;
        }
        let (bodies, report) =
            build_target(&spec, &mut |_, _, _, _| {}).map_err(|e| failed(format!("target build: {e}")))?;
        rubblepile::ellipsoid::output::write_snapshot(&out, 0.0, &bodies)
            .map_err(|e| failed(format!("{}: {e}", out.display())))?;
        let text = serde_json::to_string_pretty(&report).map_err(|e| failed(e.to_string()))?;
        rubblepile::io::safe_write::write_atomic(&json, text.clone() + "\n")
            .map_err(|e| failed(rubblepile::io::safe_write::describe(&json, &e)))?;
        Ok(text)
    });
    result.map_err(|e| e.into_py(py))
}

/// `rubblepile.build_aggregate`: `rubblepile aggregate build` (see the Python docstring); returns the report JSON text.
#[pyfunction]
#[pyo3(signature = (model, shape, out, *, particles=None, radius=None, radius_range=None, bulk_density=2100.0, core_radius=None, seed=1, lattice_orientation="perpendicular", shake_periods=None, gravity_interval=None, obj_scale=1.0, force=false))]
#[allow(clippy::too_many_arguments)]
fn build_aggregate(
    py: Python<'_>,
    model: &str,
    shape: &str,
    out: PathBuf,
    particles: Option<usize>,
    radius: Option<f64>,
    radius_range: Option<(f64, f64)>,
    bulk_density: f64,
    core_radius: Option<f64>,
    seed: u64,
    lattice_orientation: &str,
    shake_periods: Option<f64>,
    gravity_interval: Option<u64>,
    obj_scale: f64,
    force: bool,
) -> PyResult<String> {
    use rubblepile::aggregate::{
        AggregateError, BuildSpec, Grains, Model, build_with_progress, files, random_packing::Recipe, shape::Shape,
    };
    let from_aggregate = |e: AggregateError| match e {
        AggregateError::Input { .. } => Failure::scene(e.to_string()),
        AggregateError::Failed(_) => Failure {
            class: Class::Other,
            ..Failure::scene(e.to_string())
        },
    };
    let result = py.detach(|| {
        let model = Model::parse(model).ok_or_else(|| {
            Failure::scene(format!(
                "model: unknown model `{model}`; expected hcp, rcp, rcpc, pp1, pp2 or ppc"
            ))
        })?;
        let grains = match (particles, radius, radius_range) {
            (Some(n), None, None) => Grains::Count(n),
            (None, Some(r), None) => Grains::Radius(r),
            (None, None, Some((lo, hi))) => Grains::Range(lo, hi),
            _ => {
                return Err(Failure::scene(
                    "give one of particles (a count), radius (m) or radius_range ((rmin, rmax), m)".into(),
                ));
            }
        };
        files::check_outputs(&out, force).map_err(from_aggregate)?;
        let spec = BuildSpec {
            model,
            shape: Shape::parse(shape, obj_scale).map_err(|e| Failure::scene(format!("shape: {e}")))?,
            grains,
            bulk_density,
            seed,
            core_radius,
            recipe: Recipe::with_overrides(shake_periods, gravity_interval).map_err(from_aggregate)?,
            orientation: lattice_orientation
                .parse()
                .map_err(|e: String| Failure::scene(format!("lattice_orientation: {e}")))?,
        };
        let agg = build_with_progress(&spec, &mut |_| {}).map_err(from_aggregate)?;
        files::write_aggregate(&out, &agg.particles, &agg.report).map_err(from_aggregate)?;
        serde_json::to_string(&agg.report).map_err(|e| Failure::scene(e.to_string()))
    });
    result.map_err(|e| e.into_py(py))
}

/// `rubblepile.flyby`: `rubblepile flyby` (see the Python docstring): prepares, runs (and its control) and
/// analyses a flyby; returns the command line's lines.
#[pyfunction]
#[pyo3(signature = (target, out, *, q_m, v_inf_km_s=5.8, radius_m=None, period_hours=None, planet_mass=rubblepile::impact::flyby::EARTH_MASS_KG, planet_radius_m=rubblepile::impact::flyby::EARTH_RADIUS_M, planet_j2=None, planet_pole=None, orientation_deg=None, start_q=rubblepile::impact::flyby::DEFAULT_START_Q, kappa=None, f0=None, rtol=1e-6, snapshots=9, force=false, run=true, control=true, settle_to_principal=false, settle_max_hours=None))]
#[allow(clippy::too_many_arguments)]
fn flyby(
    py: Python<'_>,
    target: PathBuf,
    out: PathBuf,
    q_m: f64,
    v_inf_km_s: f64,
    radius_m: Option<f64>,
    period_hours: Option<f64>,
    planet_mass: f64,
    planet_radius_m: f64,
    planet_j2: Option<f64>,
    planet_pole: Option<Vec<f64>>,
    orientation_deg: Option<Vec<f64>>,
    start_q: f64,
    kappa: Option<f64>,
    f0: Option<f64>,
    rtol: f64,
    snapshots: usize,
    force: bool,
    run: bool,
    control: bool,
    settle_to_principal: bool,
    settle_max_hours: Option<f64>,
) -> PyResult<Vec<String>> {
    use rubblepile::analysis::flyby::{analyze_flyby, settling_line};
    use rubblepile::impact::flyby::{FlybyConfig, run_flyby};
    let cfg = FlybyConfig {
        target,
        radius_m,
        period_hours,
        planet_mass,
        planet_radius_m,
        planet_j2,
        planet_pole,
        q_m,
        v_inf_km_s,
        orientation_deg,
        start_q,
        kappa,
        f0,
        rtol,
        snapshots,
        out,
        force,
        no_run: !run,
        no_control: !control,
        settle_to_principal,
        settle_max_hours,
    };
    let options = options(false, None, None, None, None);
    let result = py.detach(|| {
        let runs = run_flyby(&cfg, &options).map_err(impact_failure)?;
        let Some(runs) = runs else {
            return Ok(vec![format!("wrote {}", cfg.out.join("scene.toml").display())]);
        };
        let o = analyze_flyby(&cfg.out).map_err(|e| Failure {
            class: Class::Other,
            ..Failure::scene(e.to_string())
        })?;
        let mut lines = Vec::new();
        lines.extend(runs.setup.settling.as_ref().map(settling_line));
        lines.push(format!("run: {}", rubblepile::engine::RunReport::one_line(&runs.run)));
        if let Some(c) = &runs.control {
            lines.push(format!(
                "control ({}): {}",
                rubblepile::impact::flyby::CONTROL_DIR,
                rubblepile::engine::RunReport::one_line(c)
            ));
        }
        lines.extend(o.lines());
        Ok::<_, Failure>(lines)
    });
    result.map_err(|e| e.into_py(py))
}

/// One grid point of a campaign as Python gets it: `campaign.csv`'s row, the run's directory and what the campaign
/// did with it.
fn campaign_row<'py>(
    py: Python<'py>,
    out: &Path,
    point: &rubblepile::impact::campaign::GridPoint,
    record: &rubblepile::impact::campaign::RunRecord,
) -> PyResult<Bound<'py, PyDict>> {
    use rubblepile::impact::campaign::{Action, RunStatus};
    let d = PyDict::new(py);
    let n = record.numbers.unwrap_or_default();
    d.set_item("run", &point.name)?;
    d.set_item("target", &point.target)?;
    d.set_item("projectile", &point.projectile)?;
    d.set_item("angle_deg", point.angle_deg)?;
    d.set_item("seed", point.seed)?;
    d.set_item("q_erg_per_g", point.plan.setup.q_erg_per_g)?;
    d.set_item("status", record.status.to_string())?;
    d.set_item("wall_seconds", n.wall_seconds)?;
    d.set_item("final_time", n.final_time)?;
    d.set_item("steps_accepted", n.steps_accepted)?;
    d.set_item("rhs_evaluations", n.rhs_evaluations)?;
    d.set_item("energy_error", n.energy_error)?;
    d.set_item("linear_momentum_error", n.linear_momentum_error)?;
    d.set_item("angular_momentum_error", n.angular_momentum_error)?;
    let action = match record.action {
        Action::Skip => "skipped",
        Action::Resume => "resumed",
        Action::Start => "started",
        Action::Conflict(_) => "conflict",
    };
    d.set_item("action", action)?;
    d.set_item("completed", record.status == RunStatus::Completed)?;
    d.set_item("stopped", record.stopped)?;
    d.set_item("dir", out.join(&point.name).display().to_string())?;
    Ok(d)
}

/// What [`campaign`] returns: the closing line, the problem (message, exit code), the campaign directory, the rows.
type CampaignOut<'py> = (String, Option<(String, u8)>, String, Vec<Bound<'py, PyDict>>);

/// `rubblepile.campaign`: `rubblepile campaign FILE` (see the Python docstring): runs the grid on this process's
/// threads and returns the campaign's one-line summary, its problem (message, exit code) if any, and one dict per
/// grid point in grid order.
#[pyfunction]
#[pyo3(signature = (file, out=None, *, parallel=None, threads_per_run=None, checkpoint_every=None, checkpoint_every_sim=None, max_steps=None, max_wall_seconds=None))]
#[allow(clippy::too_many_arguments)]
fn campaign<'py>(
    py: Python<'py>,
    file: PathBuf,
    out: Option<PathBuf>,
    parallel: Option<usize>,
    threads_per_run: Option<usize>,
    checkpoint_every: Option<f64>,
    checkpoint_every_sim: Option<f64>,
    max_steps: Option<u64>,
    max_wall_seconds: Option<f64>,
) -> PyResult<CampaignOut<'py>> {
    use rubblepile::impact::campaign::{CAMPAIGN_CSV, CampaignError, CampaignOptions, load_campaign, run_campaign};
    let failure = |e: CampaignError| {
        let mut f = Failure::scene(e.to_string());
        if e.exit_code() != 2 {
            f.class = Class::Other;
        }
        f
    };
    if parallel == Some(0) {
        return Err(Failure::scene("parallel: must be at least 1, got 0".into()).into_py(py));
    }
    if threads_per_run == Some(0) {
        return Err(Failure::scene("threads_per_run: must be at least 1, got 0".into()).into_py(py));
    }
    let result = py.detach(|| {
        let mut c = load_campaign(&file).map_err(failure)?;
        if let Some(out) = &out {
            c.out = out.clone();
        }
        let o = CampaignOptions {
            run: options(
                false,
                checkpoint_every,
                checkpoint_every_sim,
                max_steps,
                max_wall_seconds,
            ),
            parallel,
            threads_per_run,
            verbose: false,
            shard: None,
        };
        let report = run_campaign(&c, &o).map_err(failure)?;
        Ok::<_, Failure>((c, report))
    });
    let (c, report) = result.map_err(|e| e.into_py(py))?;
    let problem = report.problem(&c.out.join(CAMPAIGN_CSV));
    let rows = c
        .points
        .iter()
        .zip(&report.runs)
        .map(|(p, r)| campaign_row(py, &c.out, p, r))
        .collect::<PyResult<Vec<_>>>()?;
    Ok((report.one_line(), problem, c.out.display().to_string(), rows))
}

/// `rubblepile.critical_search`: `rubblepile spinup critical` (see the Python docstring); returns the lines the
/// command line prints (the search writes `critical.json` and `critical.csv` in `out`).
#[pyfunction]
#[pyo3(signature = (scene, out, *, from_hours, to_hours, step_hours=0.01, force=false, branch=false, criterion="paper", significance=None, coordination_tolerance=None, hold=None, judge_window=None, all_holds=false, parallel=1, threads_per_hold=None, finish_released=false))]
#[allow(clippy::too_many_arguments)]
fn critical_search(
    py: Python<'_>,
    scene: PathBuf,
    out: PathBuf,
    from_hours: f64,
    to_hours: f64,
    step_hours: f64,
    force: bool,
    branch: bool,
    criterion: &str,
    significance: Option<f64>,
    coordination_tolerance: Option<f64>,
    hold: Option<f64>,
    judge_window: Option<f64>,
    all_holds: bool,
    parallel: usize,
    threads_per_hold: Option<usize>,
    finish_released: bool,
) -> PyResult<Vec<String>> {
    use rubblepile::analysis::critical::SearchError;
    use rubblepile::experiment::critical_search::{CriticalOptions, critical};
    use rubblepile::io::messages::{Channel, default_sink, reset_sink, set_sink};
    let criterion = criterion
        .parse()
        .map_err(|e: String| Failure::scene(format!("criterion: {e}")).into_py(py))?;
    let options = CriticalOptions {
        force,
        branch,
        criterion,
        coordination_tolerance,
        significance,
        hold,
        judge_window,
        all_holds,
        parallel,
        threads_per_hold,
        finish_released,
        ..CriticalOptions::new(scene, from_hours, to_hours, step_hours, out)
    };
    // The search's result lines (the command line's stdout) are collected; progress and warnings go where they
    // always go.
    let lines = std::sync::Arc::new(Mutex::new(Vec::<String>::new()));
    let sink_lines = lines.clone();
    set_sink(move |channel, line| match channel {
        Channel::Out => sink_lines
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(line.to_string()),
        other => default_sink(other, line),
    });
    let result = py.detach(|| critical(&options));
    reset_sink();
    result.map_err(|e| match e {
        SearchError::Usage(m) => Failure::scene(m).into_py(py),
        SearchError::Failed(m) => RubblepileError::new_err(m),
    })?;
    let lines = lines.lock().unwrap_or_else(|e| e.into_inner()).clone();
    Ok(lines)
}

/// The extension module.
#[pymodule]
fn _rubblepile(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("RubblepileError", py.get_type::<RubblepileError>())?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add("RunFailed", py.get_type::<RunFailed>())?;
    m.add("RunStopped", py.get_type::<RunStopped>())?;
    m.add_class::<Simulation>()?;
    m.add_function(wrap_pyfunction!(impact, m)?)?;
    m.add_function(wrap_pyfunction!(analyze, m)?)?;
    m.add_function(wrap_pyfunction!(build_target, m)?)?;
    m.add_function(wrap_pyfunction!(build_aggregate, m)?)?;
    m.add_function(wrap_pyfunction!(flyby, m)?)?;
    m.add_function(wrap_pyfunction!(campaign, m)?)?;
    m.add_function(wrap_pyfunction!(critical_search, m)?)?;
    Ok(())
}
