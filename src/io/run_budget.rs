//! A run's budget, so that a run ends within stated limits rather than crawling on: the `[run]` table every
//! engine's scene file accepts, and the limits the run driver holds a run to.
//!
//! - `max_steps`: the most steps a run may take (integrator step attempts of the ellipsoids, fixed steps of the
//!   spheres), [`DEFAULT_MAX_STEPS`] unless the scene (`[run] max_steps`) or the command line (`--max-steps`) says
//!   otherwise. A scene whose own work estimate exceeds it is refused before it starts; a run that reaches it stops
//!   at the next output sample with a checkpoint, naming the budget (and an ellipsoid integrator is never let take
//!   more steps than are left within one sample interval).
//! - `max_wall_seconds`: the most wall-clock seconds this process may run a run (`[run] max_wall_seconds`,
//!   `--max-wall-s`); none by default. The run stops with a checkpoint at the output sample after which the
//!   next interval would overrun it (judged by the last one), or at the first sample past it.
//!
//! [`check_interval`] checks the time options of the command line (cadences, budgets) against their floors and
//! ceilings ([`crate::io::limits`]).
//!
//! A budget stop leaves a checkpoint (unless the run ended first): `rubblepile resume DIR` with a larger budget
//! continues it, bit for bit as if it had not stopped.

use scene_derive::SceneFields;
use serde::{Deserialize, Serialize};

use crate::io::scene_file::{SceneError, Validator};

/// The step budget of a run when neither the scene nor the command line sets one: 1e9 steps, the work above which
/// scenes were already warned about ([`crate::io::limits::WORK_WARNING_STEPS`]): at ~1e5 steps per second of the
/// fastest scenes, hours; at the speed of a large pile, days.
pub const DEFAULT_MAX_STEPS: u64 = 1_000_000_000;

/// The largest `max_steps` accepted: 1e15 steps, decades at any speed this code reaches; a larger value is a typo.
pub const MAX_MAX_STEPS: u64 = 1_000_000_000_000_000;

/// The shortest wall-clock budget accepted (s): a run needs at least this long to write anything useful.
pub const MIN_WALL_BUDGET: f64 = 1.0;

/// The longest wall-clock budget accepted (s), and the longest wall-clock interval any time option accepts
/// ([`crate::io::limits::MAX_WALL_INTERVAL`]).
pub const MAX_WALL_BUDGET: f64 = crate::io::limits::MAX_WALL_INTERVAL;

/// `value` of the time option `name` when it is in [`lo`, `hi`] (in `unit`), or `0` when `off` says 0 is allowed
/// (and what it means); otherwise one line naming the option, the range and the value, whatever the value (NaN,
/// infinite, subnormal or huge: nothing converts it before it is checked).
pub fn check_interval(name: &str, value: f64, lo: f64, hi: f64, unit: &str, off: Option<&str>) -> Result<f64, String> {
    if (off.is_some() && value == 0.0) || (value >= lo && value <= hi) {
        return Ok(value);
    }
    let zero = off.map_or(String::new(), |what| format!("0 ({what}) or "));
    Err(format!(
        "{name} must be {zero}a number of {unit} from {lo} to {hi:e}, got {}",
        crate::io::scene_file::fmt_num(value)
    ))
}

/// A wall-clock cadence option `name` (s): 0 (`off` says what 0 means) or [`crate::io::limits::MIN_WALL_INTERVAL`]
/// to [`crate::io::limits::MAX_WALL_INTERVAL`] ([`check_interval`]).
pub fn check_wall_seconds(name: &str, value: f64, off: &str) -> Result<f64, String> {
    use crate::io::limits::{MAX_WALL_INTERVAL, MIN_WALL_INTERVAL};
    check_interval(name, value, MIN_WALL_INTERVAL, MAX_WALL_INTERVAL, "seconds", Some(off))
}

/// The time options and the budget of a run as the command line gives them (`--checkpoint-every-s`,
/// `--checkpoint-every-sim-s`, `--progress-every-s`, `--max-steps`, `--max-wall-s`), before they are checked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeOptions {
    /// Wall-clock checkpoint cadence (s; 0 = never).
    pub checkpoint_every: f64,
    /// Simulated-time checkpoint cadence (s).
    pub checkpoint_every_sim: Option<f64>,
    /// Seconds between progress lines (0 = none).
    pub progress_every: Option<f64>,
    /// Most steps (a whole number, given as a number).
    pub max_steps: Option<f64>,
    /// Most wall-clock seconds.
    pub max_wall_seconds: Option<f64>,
}

impl TimeOptions {
    /// The options checked against their floors and ceilings ([`crate::io::limits`], this module), the first one
    /// outside them refused in one line naming it; `checkpoint_every` 0 becomes `None` (never).
    pub fn check(&self) -> Result<TimeOptions, String> {
        use crate::io::limits::{MAX_SIM_INTERVAL, MAX_WALL_INTERVAL, MIN_PROGRESS_EVERY};
        let every = check_wall_seconds("--checkpoint-every-s", self.checkpoint_every, "never")?;
        let sim = |s| {
            check_interval(
                "--checkpoint-every-sim-s",
                s,
                0.0,
                MAX_SIM_INTERVAL,
                "simulated seconds",
                None,
            )
        };
        let progress = |s| {
            check_interval(
                "--progress-every-s",
                s,
                MIN_PROGRESS_EVERY,
                MAX_WALL_INTERVAL,
                "seconds",
                Some("no lines"),
            )
        };
        let wall = |s| check_interval("--max-wall-s", s, MIN_WALL_BUDGET, MAX_WALL_BUDGET, "seconds", None);
        Ok(TimeOptions {
            checkpoint_every: every,
            checkpoint_every_sim: self.checkpoint_every_sim.map(sim).transpose()?,
            progress_every: self.progress_every.map(progress).transpose()?,
            max_steps: self
                .max_steps
                .map(|n| check_max_steps(n).map(|n| n as f64))
                .transpose()?,
            max_wall_seconds: self.max_wall_seconds.map(wall).transpose()?,
        })
    }
}

/// `n` of `--max-steps` as a count of steps: a whole number in [1, [`MAX_MAX_STEPS`]] (given as a number, so that
/// `1e10` is accepted), or one line saying so.
pub fn check_max_steps(n: f64) -> Result<u64, String> {
    if n.is_finite() && n.fract() == 0.0 && (1.0..=MAX_MAX_STEPS as f64).contains(&n) {
        Ok(n as u64)
    } else {
        Err(format!(
            "--max-steps must be a whole number of steps from 1 to {:e}, got {}",
            MAX_MAX_STEPS as f64,
            crate::io::scene_file::fmt_num(n)
        ))
    }
}

/// `[run]` of a scene file. Optional; both keys optional.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize, SceneFields)]
#[scene(table = "run")]
#[serde(deny_unknown_fields)]
pub struct RunSection {
    /// most steps the run may take; a scene estimated to need more is refused, a run reaching it stops with a
    /// checkpoint (also --max-steps)
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "count", default = "1e9", range = closed(1.0, MAX_MAX_STEPS as f64))]
    pub max_steps: Option<u64>,
    /// Most wall-clock seconds a process may run the run (none when absent), in [[`MIN_WALL_BUDGET`],
    /// [`MAX_WALL_BUDGET`]].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[field(unit = "s", default = "none", range = closed(MIN_WALL_BUDGET, MAX_WALL_BUDGET))]
    #[field(
        meaning = "most wall-clock seconds a process may run it; it stops with a checkpoint before overrunning (also \
                   --max-wall-s)"
    )]
    pub max_wall_seconds: Option<f64>,
}

impl RunSection {
    /// Whether the table sets nothing (it is then not written when a scene is written anew).
    pub fn is_empty(&self) -> bool {
        *self == RunSection::default()
    }
}

/// Checks the `[run]` table of a scene, naming the field.
pub(crate) fn validate(v: &Validator<'_>, run: &RunSection) -> Result<(), SceneError> {
    if let Some(n) = run.max_steps {
        v.field(&RunSection::MAX_STEPS, n as f64)?;
    }
    if let Some(s) = run.max_wall_seconds {
        v.field(&RunSection::MAX_WALL_SECONDS, s)?;
    }
    Ok(())
}

/// The `[run]` table of a scene's text (as every engine has validated it); empty when there is none or the text
/// cannot be read (the engine's own reading names what is wrong).
pub fn from_scene_text(text: &str) -> RunSection {
    text.parse::<toml::Table>()
        .ok()
        .and_then(|t| t.get("run").cloned())
        .and_then(|r| r.try_into().ok())
        .unwrap_or_default()
}

/// The budget a run is held to: the command line's values over the scene's, [`DEFAULT_MAX_STEPS`] steps and no
/// wall-clock limit by default.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Budget {
    /// Most steps.
    pub max_steps: u64,
    /// Where `max_steps` came from, for messages (`--max-steps`, `[run] max_steps`, `the default`).
    pub steps_from: &'static str,
    /// Most wall-clock seconds of this process.
    pub max_wall_seconds: Option<f64>,
}

impl Budget {
    /// The budget of a run of a scene with `[run]` table `scene`, the command line giving `max_steps` and
    /// `max_wall_seconds` (checked by the command line).
    pub fn resolve(scene: RunSection, max_steps: Option<u64>, max_wall_seconds: Option<f64>) -> Budget {
        let (max_steps, steps_from) = match (max_steps, scene.max_steps) {
            (Some(n), _) => (n, "--max-steps"),
            (None, Some(n)) => (n, "[run] max_steps"),
            (None, None) => (DEFAULT_MAX_STEPS, "the default ceiling"),
        };
        Budget {
            max_steps,
            steps_from,
            max_wall_seconds: max_wall_seconds.or(scene.max_wall_seconds),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_command_line_wins_over_the_scene_and_the_default_is_the_ceiling() {
        let scene = from_scene_text("[scene]\nt_end = 1.0\n[run]\nmax_steps = 5000\nmax_wall_seconds = 60.0\n");
        assert_eq!(scene.max_steps, Some(5000));
        let b = Budget::resolve(scene, None, None);
        assert_eq!(
            (b.max_steps, b.steps_from, b.max_wall_seconds),
            (5000, "[run] max_steps", Some(60.0))
        );
        let b = Budget::resolve(scene, Some(7), Some(2.0));
        assert_eq!((b.max_steps, b.max_wall_seconds), (7, Some(2.0)));
        let b = Budget::resolve(RunSection::default(), None, None);
        assert_eq!((b.max_steps, b.max_wall_seconds), (DEFAULT_MAX_STEPS, None));
        assert!(from_scene_text("not toml [").is_empty());
    }
}
