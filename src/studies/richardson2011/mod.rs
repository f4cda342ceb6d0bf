//! Richardson et al. (2011, Icarus 212) §3: the report on the model atmosphere and the tumbler ([`report`]) and the
//! tumbler at the paper's own scale ([`tumbler_paper`]).

pub mod atmosphere;
pub mod report;
pub mod tumbler;
pub mod tumbler_paper;
#[cfg(test)]
mod tumbler_tests;
