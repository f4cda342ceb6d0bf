//! Roig et al. (2003, Icarus 165) §4: the reproduction report ([`report`]) and its κ section ([`kappa`]).

pub mod ejection_fits;
pub mod kappa;
pub mod pile_equilibrium;
pub mod referee;
#[cfg(test)]
mod referee_analysis_tests;
pub mod report;
pub mod rotational_split;
