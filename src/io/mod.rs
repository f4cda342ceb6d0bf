//! The engine-independent floor of file input and output: lossless float formatting ([`fmt_f64`]), the checkpoint
//! file names ([`checkpoint`]), the scene-file reading, parsing and field checks every engine's scene uses
//! ([`scene_file`]), and the one-writer lock of the directories rubblepile writes ([`run_lock`]). Each engine's own
//! output formats live with the engine (e.g. `ellipsoid::output`).
//!
//! Floats are written with `{:e}` (Rust's shortest representation that round-trips, in scientific notation), so a
//! snapshot re-read as an input file gives the same `f64`s bit for bit.

pub mod checkpoint;
pub mod particles;
pub mod run_lock;
pub mod scene_file;
pub mod ss;
pub mod table;
pub mod vtk;

/// Formats an `f64` losslessly: the shortest decimal that parses back to the same bits (`{:e}`).
pub fn fmt_f64(x: f64) -> String {
    format!("{x:e}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fmt_f64_round_trips() {
        for x in [
            0.0,
            -0.0,
            1.0,
            0.1,
            1.0 / 3.0,
            6.674e-11,
            1e300,
            -2.5e-310,
            f64::MAX,
            f64::MIN_POSITIVE,
        ] {
            let s = fmt_f64(x);
            let y: f64 = s.parse().unwrap();
            assert_eq!(x.to_bits(), y.to_bits(), "{x} -> {s}");
        }
    }
}
