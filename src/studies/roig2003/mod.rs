//! Roig et al. (2003, Icarus 165) §4: the reproduction report ([`report`]) and its κ section ([`kappa`]).

pub mod kappa;
pub mod referee;
pub mod report;
