//! Zhang et al. (2017, Icarus 294): the report on Table 3's critical spin limits ([`report`]), its spin-up-path
//! section after Table 6 ([`paths`]), the resolution ladder ([`ladder`]), the packing ordering under changed contact
//! laws ([`ordering`]), Table 7's materials ([`materials`]), the Fig. 22 analogue of the searches' holds ([`holds`])
//! the study that decides the paper's Table 3 at its scale ([`decided`]) and the commands that judge its searches
//! again ([`spinup_tools`]),
//! all reading runs into the rows
//! of [`rows`]. The searches that make its runs are generic and live in
//! [`rubblepile::analysis::critical`].

pub mod body;
pub mod creep_extrapolation;
pub mod decided;
pub mod holds;
pub mod ladder;
pub mod materials;
pub mod ordering;
pub mod paths;
pub mod report;
#[cfg(test)]
mod report_tests;
pub mod rows;
pub mod settling;
pub mod spin_limit;
pub mod spinup_figures;
pub mod spinup_tools;
pub mod surface_slopes;
