//! The three papers this crate reproduces, one room each: the code that writes a paper's report (its tables beside
//! the paper's numbers, its referee sections, its figures), built on the post-processing of [`rubblepile::analysis`] that
//! any run needs.
//!
//! - [`roig2003`]: Roig et al. (2003, Icarus 165), §4 — `rubblepile report roig2003`;
//! - [`zhang2017`]: Zhang et al. (2017, Icarus 294), Tables 3 and 6 — `rubblepile report zhang2017`;
//! - [`richardson2011`]: Richardson et al. (2011, Icarus 212, 427), §3.1–3.2 — `rubblepile report richardson2011` and
//!   `richardson2011-tumbler`;
//! - [`report_notes`]: the hand-written `NOTES.md` the Zhang17 and Richardson11 reports append.

pub mod csv_rows;
pub mod report_notes;
pub mod richardson2011;
pub mod roig2003;
pub mod zhang2017;
