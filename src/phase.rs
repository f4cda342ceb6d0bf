//! Where the time goes: wall time per named phase of the engines' hot loops, each phase marked serial (one thread
//! works, the others wait) or parallel (a fork–join region), so that a benchmark can state the serial fraction of an
//! evaluation from measurements (Amdahl's law) beside the one inferred from its speed-ups (Karp–Flatt).
//!
//! A phase is a `static` [`Phase`] next to the code it times. [`Phase::time`] costs one relaxed atomic load when
//! timing is off (the default), so the probes stay in release builds; `rubblepile bench scaling` turns timing on
//! with [`enable`], runs, and reads [`totals`]. Phases are leaves: they are not nested, and each is timed on the
//! thread that enters it, so on one thread the phases of an evaluation add up to (nearly) its wall time. Two
//! branches of a `rayon::join` that run at once on several threads are both counted in full; read the split at one
//! thread, where it is exact.
//!
//! The bottom floor of the crate: it imports nothing from it.

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

/// Whether a phase runs on one thread or forks work over the pool.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// One thread works while the others wait: it bounds the speed-up (Amdahl).
    Serial,
    /// A fork–join region over the pool.
    Parallel,
}

impl Kind {
    /// `"serial"` or `"parallel"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Kind::Serial => "serial",
            Kind::Parallel => "parallel",
        }
    }
}

/// One named phase: its kind and the wall time (ns) and calls summed while timing was on.
#[derive(Debug)]
pub struct Phase {
    /// Dotted name, engine first (`"ellipsoid.pair_forces"`).
    pub name: &'static str,
    /// Serial or parallel.
    pub kind: Kind,
    nanos: AtomicU64,
    calls: AtomicU64,
    registered: AtomicBool,
}

/// Timing on or off (off by default).
static ENABLED: AtomicBool = AtomicBool::new(false);

/// Every phase timed since the process started, in the order they were first timed.
static REGISTRY: Mutex<Vec<&'static Phase>> = Mutex::new(Vec::new());

impl Phase {
    /// A phase with no time recorded.
    pub const fn new(name: &'static str, kind: Kind) -> Phase {
        Phase {
            name,
            kind,
            nanos: AtomicU64::new(0),
            calls: AtomicU64::new(0),
            registered: AtomicBool::new(false),
        }
    }

    /// Runs `f`, adding its wall time to the phase when timing is on.
    #[inline]
    pub fn time<R>(&'static self, f: impl FnOnce() -> R) -> R {
        if !ENABLED.load(Ordering::Relaxed) {
            return f();
        }
        let start = Instant::now();
        let r = f();
        self.record(start.elapsed().as_nanos() as u64);
        r
    }

    /// Adds `nanos` of wall time and one call (registering the phase on its first record).
    pub fn record(&'static self, nanos: u64) {
        if !self.registered.swap(true, Ordering::AcqRel) {
            REGISTRY.lock().unwrap_or_else(|e| e.into_inner()).push(self);
        }
        self.nanos.fetch_add(nanos, Ordering::Relaxed);
        self.calls.fetch_add(1, Ordering::Relaxed);
    }
}

/// Turns timing on or off for the whole process.
pub fn enable(on: bool) {
    ENABLED.store(on, Ordering::Relaxed);
}

/// Whether timing is on.
pub fn enabled() -> bool {
    ENABLED.load(Ordering::Relaxed)
}

/// The time summed in one phase.
#[derive(Debug, Clone, PartialEq)]
pub struct Total {
    /// The phase's name.
    pub name: &'static str,
    /// Serial or parallel.
    pub kind: Kind,
    /// Wall time (s).
    pub seconds: f64,
    /// Times the phase ran.
    pub calls: u64,
}

/// The totals of every phase timed so far, in the order the phases were first timed.
pub fn totals() -> Vec<Total> {
    let registry = REGISTRY.lock().unwrap_or_else(|e| e.into_inner());
    registry
        .iter()
        .map(|p| Total {
            name: p.name,
            kind: p.kind,
            seconds: p.nanos.load(Ordering::Relaxed) as f64 * 1e-9,
            calls: p.calls.load(Ordering::Relaxed),
        })
        .collect()
}

/// Sets every phase's time and calls back to zero.
pub fn reset() {
    let registry = REGISTRY.lock().unwrap_or_else(|e| e.into_inner());
    for p in registry.iter() {
        p.nanos.store(0, Ordering::Relaxed);
        p.calls.store(0, Ordering::Relaxed);
    }
}

/// The totals of the phases whose name starts with `prefix` (an engine's: `"ellipsoid."`), and their serial and
/// parallel sums (s).
pub fn split(prefix: &str) -> (Vec<Total>, f64, f64) {
    let mine: Vec<Total> = totals().into_iter().filter(|t| t.name.starts_with(prefix)).collect();
    let sum = |kind: Kind| mine.iter().filter(|t| t.kind == kind).map(|t| t.seconds).sum();
    let (serial, parallel) = (sum(Kind::Serial), sum(Kind::Parallel));
    (mine, serial, parallel)
}

#[cfg(test)]
mod tests {
    use super::*;

    static WORK: Phase = Phase::new("test.work", Kind::Serial);
    static IDLE: Phase = Phase::new("test.idle", Kind::Parallel);

    /// Timing off records nothing; on, it records every call and the time spent; reset clears it.
    #[test]
    fn records_only_while_enabled() {
        enable(false);
        assert_eq!(WORK.time(|| 7), 7);
        assert!(split("test.").0.is_empty(), "nothing is registered while off");
        enable(true);
        WORK.time(|| std::thread::sleep(std::time::Duration::from_millis(2)));
        WORK.time(|| ());
        IDLE.time(|| ());
        enable(false);
        let (mine, serial, parallel) = split("test.");
        let work = mine.iter().find(|t| t.name == "test.work").unwrap();
        assert_eq!(work.calls, 2);
        assert!(serial >= 2e-3, "the sleep is counted: {serial}");
        assert!(parallel < serial);
        reset();
        assert!(split("test.").0.iter().all(|t| t.calls == 0 && t.seconds == 0.0));
    }
}
