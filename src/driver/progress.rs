//! How a run shows its progress on stderr: the indicatif bar on a terminal, and on anything else (a batch job's log,
//! a pipe) one plain line every few seconds of wall clock — simulated time, per cent done, ETA and the engine's
//! error so far — so a log is not silent until `done:`.

use std::cell::Cell;
use std::io::IsTerminal;
use std::time::{Duration, Instant};

use crate::io::messages::{Channel, emit};

/// Default wall-clock seconds between progress lines on a non-terminal (the runner's `RunOptions::progress_every`).
pub const DEFAULT_PROGRESS_EVERY: f64 = 60.0;

/// The environment variable that sets the seconds between progress lines when `--progress-every-s` is not given.
pub const PROGRESS_EVERY_ENV: &str = "RUBBLEPILE_PROGRESS_EVERY";

/// The cadence [`PROGRESS_EVERY_ENV`] sets (its text `text`): 0 (no lines) or 0.1 to 1e7 s
/// ([`crate::io::limits::MIN_PROGRESS_EVERY`], [`crate::io::limits::MAX_WALL_INTERVAL`]); otherwise one line naming
/// the variable and quoting its text.
pub fn every_from_env(text: &str) -> Result<f64, String> {
    use crate::io::limits::{MAX_WALL_INTERVAL, MIN_PROGRESS_EVERY};
    let value = text.trim().parse::<f64>().unwrap_or(f64::NAN);
    if value == 0.0 || (MIN_PROGRESS_EVERY..=MAX_WALL_INTERVAL).contains(&value) {
        return Ok(value);
    }
    Err(format!(
        "{PROGRESS_EVERY_ENV} must be 0 (no lines) or a number of seconds from {MIN_PROGRESS_EVERY} to \
         {MAX_WALL_INTERVAL:e}, got {text:?}"
    ))
}

/// A progress display for a run from `t` to `t_end` (s).
pub enum Progress {
    /// Nothing shown (`--no-progress`, or lines turned off with a cadence of 0).
    Off,
    /// The bar, on a terminal.
    Bar(indicatif::ProgressBar),
    /// Plain lines on a non-terminal.
    Lines(Lines),
}

/// The state of the plain progress lines.
pub struct Lines {
    every: Duration,
    started: Instant,
    // A cell: the run's failure path and its progress callback both hold the display.
    last: Cell<Instant>,
    t_start: f64,
    label: Option<&'static str>,
}

impl Progress {
    /// The bar when `enabled` and stderr is a terminal; lines every `every` wall-clock seconds when `enabled`,
    /// stderr is not a terminal and `every > 0`; otherwise nothing. `label` names the run in each line and in the
    /// bar's message (a flyby's `run` and `control`, which run one after the other).
    pub fn new(enabled: bool, every: f64, t_end: f64, t: f64, label: Option<&'static str>) -> Progress {
        if !enabled {
            Progress::Off
        } else if std::io::stderr().is_terminal() {
            progress_bar(true, t_end, t).map_or(Progress::Off, |pb| {
                if let Some(l) = label {
                    pb.set_prefix(l);
                }
                Progress::Bar(pb)
            })
        } else if every.is_finite() && every > 0.0 {
            let now = Instant::now();
            Progress::Lines(Lines {
                // Never a panic, whatever a library caller passes (the command line bounds it first).
                every: Duration::try_from_secs_f64(every).unwrap_or(Duration::MAX),
                started: now,
                last: Cell::new(now),
                t_start: t,
                label,
            })
        } else {
            Progress::Off
        }
    }

    /// Shows simulated time `t` of `t_end` (s); `error` is the engine's error measure so far (name, value), for the
    /// lines. A line is printed only when `every` seconds have passed since the last (or the start).
    pub fn show(&self, t: f64, t_end: f64, error: Option<(&str, f64)>) {
        match self {
            Progress::Off => {}
            Progress::Bar(pb) => show_progress(pb, t, t_end),
            Progress::Lines(lines) => {
                if lines.last.get().elapsed() >= lines.every {
                    lines.last.set(Instant::now());
                    emit(
                        Channel::Progress,
                        &labelled(
                            lines.label,
                            progress_line(t, t_end, lines.t_start, lines.started.elapsed(), error),
                        ),
                    );
                }
            }
        }
    }

    /// Clears the bar at the end of a completed run (the summary line follows); nothing for lines.
    pub fn finish(&self) {
        if let Progress::Bar(pb) = self {
            pb.finish_and_clear();
        }
    }

    /// Leaves the bar as it is (a failed run); nothing for lines.
    pub fn abandon(&self) {
        if let Progress::Bar(pb) = self {
            pb.abandon();
        }
    }
}

/// One progress line: `progress: t = 120 of 600 s (20.0 %), wall 1m 0s, ETA 4m 0s, energy error 3.1e-12`. The ETA
/// assumes the rest runs as fast as the simulated time from `t_start` did over `wall`.
pub fn progress_line(t: f64, t_end: f64, t_start: f64, wall: Duration, error: Option<(&str, f64)>) -> String {
    let done = if t_end > 0.0 { 100.0 * t / t_end } else { 100.0 };
    let w = wall.as_secs_f64();
    let eta = if t > t_start && t_end > t {
        clock(w * (t_end - t) / (t - t_start))
    } else if t >= t_end {
        "0s".to_string()
    } else {
        "unknown".to_string()
    };
    let mut line = format!(
        "progress: t = {} of {} s ({done:.1} %), wall {}, ETA {eta}",
        // Four decimals are plenty for a log; an adaptive step's time has sixteen.
        fmt_time(t),
        fmt_time(t_end),
        clock(w)
    );
    if let Some((name, value)) = error {
        line.push_str(&format!(", {name} {value:.1e}"));
    }
    line
}

/// A progress line of the run named `label`: `progress: control: t = …` (unchanged without a label).
pub fn labelled(label: Option<&str>, line: String) -> String {
    match label {
        Some(l) => line.replacen("progress: ", &format!("progress: {l}: "), 1),
        None => line,
    }
}

pub use crate::io::messages::fmt_time;

/// Seconds as `2h 5m 3s`, `5m 3s` or `3s` (whole seconds).
fn clock(s: f64) -> String {
    let s = s.max(0.0).round() as u64;
    match (s / 3600, (s % 3600) / 60, s % 60) {
        (0, 0, sec) => format!("{sec}s"),
        (0, m, sec) => format!("{m}m {sec}s"),
        (h, m, sec) => format!("{h}h {m}m {sec}s"),
    }
}

/// A progress bar on stderr for a run from `t` to `t_end` (s), when `enabled` and stderr is a terminal.
pub fn progress_bar(enabled: bool, t_end: f64, t: f64) -> Option<indicatif::ProgressBar> {
    if !enabled || !std::io::stderr().is_terminal() {
        return None;
    }
    let pb = indicatif::ProgressBar::with_draw_target(Some(1_000_000), indicatif::ProgressDrawTarget::stderr());
    let style =
        indicatif::ProgressStyle::with_template("{spinner} {prefix} [{elapsed_precise}] {wide_bar} {msg} ETA {eta}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
    pb.set_style(style);
    pb.set_position((t / t_end * 1e6) as u64);
    pb.reset_eta();
    pb.set_message(format!("t = {}/{} s", fmt_time(t), fmt_time(t_end)));
    pb.enable_steady_tick(Duration::from_millis(250));
    Some(pb)
}

/// Moves `pb` to simulated time `t` of `t_end` (s).
pub fn show_progress(pb: &indicatif::ProgressBar, t: f64, t_end: f64) {
    pb.set_position((t / t_end * 1e6) as u64);
    pb.set_message(format!("t = {}/{} s", fmt_time(t), fmt_time(t_end)));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_says_time_share_eta_and_error() {
        let line = progress_line(
            150.0,
            600.0,
            0.0,
            Duration::from_secs(60),
            Some(("energy error", 3.14e-12)),
        );
        // 150 s of simulated time took 60 s: the other 450 s take 180 s.
        assert_eq!(
            line,
            "progress: t = 150 of 600 s (25.0 %), wall 1m 0s, ETA 3m 0s, energy error 3.1e-12"
        );
        // A resumed run measures its speed from where it resumed.
        let line = progress_line(400.0, 600.0, 300.0, Duration::from_secs(7300), None);
        assert_eq!(
            line,
            "progress: t = 400 of 600 s (66.7 %), wall 2h 1m 40s, ETA 4h 3m 20s"
        );
        let line = progress_line(0.0, 600.0, 0.0, Duration::from_secs(5), None);
        assert!(line.ends_with("ETA unknown"), "{line}");
    }

    /// Issue 57: times made of steps print rounded, not with their round-off digits.
    /// A flyby's run and control each go from 0 to 100 %: their lines say which is which; an unnamed run's are as
    /// before.
    #[test]
    fn progress_lines_of_a_named_run_say_its_name() {
        let line = progress_line(3.0, 6.0, 0.0, Duration::from_secs(1), None);
        assert!(labelled(Some("control"), line.clone()).starts_with("progress: control: t = 3 of 6 s"));
        assert_eq!(labelled(None, line.clone()), line);
    }

    #[test]
    fn fmt_time_prints_six_significant_digits() {
        assert_eq!(format!("{}", 3.0 * 1.1), "3.3000000000000003");
        assert_eq!(fmt_time(3.0 * 1.1), "3.3");
        assert_eq!(fmt_time(3931.2 + 4.6e-13), "3931.2");
        assert_eq!(fmt_time(120.0), "120");
        assert_eq!(fmt_time(0.1 + 0.2), "0.3");
        assert_eq!(fmt_time(1.23456789), "1.23457");
        // a flyby's adaptive end time and its progress total once printed 17 and 10 digits
        assert_eq!(fmt_time(48234.652155108546), "48234.7");
        assert_eq!(fmt_time(122782.7643), "122783");
        assert_eq!(fmt_time(0.999996), "0.999996");
        assert_eq!(fmt_time(1234567.0), "1234567");
        assert_eq!(fmt_time(-0.0), "0");
        assert_eq!(fmt_time(f64::INFINITY), "inf");
        let line = progress_line(3.0 * 1.1, 6.0 * 1.1, 0.0, Duration::from_secs(60), None);
        assert!(line.starts_with("progress: t = 3.3 of 6.6 s (50.0 %)"), "{line}");
    }
}
