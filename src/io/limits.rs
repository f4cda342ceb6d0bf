//! The physical constants and limits every engine's scene uses (the SI `G`, the smallest tolerance, size, step,
//! the largest counts and input sizes), one rule per engine-neutral concept, so that every input is bounded, finite
//! and named. They sit in a file of their own, below `io::scene_file` (which re-exports them and checks scenes
//! against them) and `io::output_times` (which checks a snapshot cadence), so that both read them one way.

/// The SI gravitational constant used when a scene gives none (m³ kg⁻¹ s⁻²).
pub const SI_G: f64 = 6.674e-11;

/// Smallest relative tolerance accepted: below it the integrators' error estimates are dominated by round-off
/// (f64 epsilon is 2.2e-16, and a Bulirsch–Stoer estimate sums many such terms).
pub const MIN_RTOL: f64 = 1e-15;

/// Most time-series rows a scene may ask for (`t_end / every`): a row is ~200 bytes, so 1e8 rows are ~20 GB of
/// `timeseries.csv`, far beyond any analysis here; a larger count is a typo (a cadence in the wrong unit).
pub const MAX_TIMESERIES_ROWS: f64 = 1e8;

/// The smallest meaningful magnitude (1e-300) of a positive physical size (a length, mass, density, time, spring
/// constant, …). Below it the squares and products the engines form (a moment of inertia `m r²`, a volume `A B C`)
/// underflow to zero or to subnormals that carry no precision, and a division by them gives infinities, so such a
/// value is refused at validation rather than ending as a non-finite state that names no input. Committed scenes
/// use sizes above 1e-12.
pub const MIN_MEANINGFUL: f64 = 1e-300;

/// Smallest time step or output cadence relative to the run's length: a step or cadence below `t_end × 1e-12`
/// means more than 1e12 steps (or samples), years of wall-clock time at any speed this code reaches (the soft
/// spheres advance ~1e7 particle-steps per second); it is a typo or a subnormal, never a run that ends.
pub const MIN_STEP_FRACTION: f64 = 1e-12;

/// Most snapshots a scene (or `rubblepile flyby --snapshots`) may ask for: each is a file of one row per body, so
/// 1e5 snapshots of the smallest scene already fill a directory with 1e5 files; the committed runs write at most
/// a few hundred.
pub const MAX_SNAPSHOTS: usize = 100_000;

/// Most bodies or particles a scene (its tables, its bodies or particles file) may hold: 1e7 bodies take a few GB
/// of state and derivatives, beyond what one machine integrates in useful time (the largest committed pile has
/// 1e4 ellipsoids, the largest soft-sphere runs ~1e5 spheres).
pub const MAX_BODIES: usize = 10_000_000;

/// Largest `stepping.max_events_per_step` of the hard spheres: the guard that names a stalled step is useless if
/// it lets one step process more events than run in hours (~1e6 events per second).
pub const MAX_EVENTS_PER_STEP: u64 = 1_000_000_000;

/// Estimated steps (integrator steps of the ellipsoids, fixed steps of the spheres) above which a scene is
/// reported with a `warning:` by `check` and at the start of `run`: at ~1e5 steps per second of the fastest
/// scenes this is hours, and a run that crawls must not be silent. Big runs stay legitimate: it only warns.
pub const WORK_WARNING_STEPS: f64 = 1e9;

/// Largest input file read (bytes): 4 GiB, the size of a particles file of [`MAX_BODIES`] rows at ~400 bytes a
/// row. Files are read through `scene_file::BoundedReader`, so a device like `/dev/zero` or a runaway file is refused
/// instead of read until the allocator aborts.
pub const MAX_INPUT_BYTES: u64 = 4 << 30;

/// Longest line of a text input file (bytes): 16 MiB holds a `times = […]` list of [`MAX_SNAPSHOTS`] numbers on
/// one line with room to spare, and a CSV row of the widest table is a few kB. A longer "line" is not a text file
/// (e.g. `/dev/zero`, which has none), and is refused after reading 16 MiB instead of all memory.
pub const MAX_LINE_BYTES: usize = 16 << 20;

/// Most threads a command-line option may ask for (`--threads`, `--threads-per-rank`): the benches' bound.
pub const MAX_THREADS: usize = 4096;

/// Shortest wall-clock interval (s) of a time option other than "off" (`--checkpoint-every-s`): a millisecond. Below
/// it a value is a typo or a subnormal (1e-320), never a cadence anyone wants.
pub const MIN_WALL_INTERVAL: f64 = 1e-3;

/// Shortest interval between progress lines (s; `--progress-every-s`, `RUBBLEPILE_PROGRESS_EVERY`): a tenth of a
/// second, so a batch log gets at most ten lines a second (a cadence of 1e-320 once wrote 125 801 lines).
pub const MIN_PROGRESS_EVERY: f64 = 0.1;

/// Longest wall-clock interval (s) any time option or budget accepts: 1e7 s (116 days), beyond any batch job's
/// limit; a larger value is a typo (and 1e308 overflowed the conversion to a `Duration`).
pub const MAX_WALL_INTERVAL: f64 = 1e7;

/// Longest simulated-time interval (s) a time option accepts (`--checkpoint-every-sim-s`): 1e18 s, longer than any
/// scene's `t_end` worth running; it must be finite.
pub const MAX_SIM_INTERVAL: f64 = 1e18;
