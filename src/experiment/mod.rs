//! Experiments that run many simulations and judge them with the analysis: the search for a pile's third critical
//! spin limit T_c,3 (Zhang17 §3.3.3), whose holds branch off one spin-up run and run in parallel.

pub mod critical_search;
