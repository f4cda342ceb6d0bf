//! Zhang et al. (2017, Icarus 294): the report on Table 3's critical spin limits ([`report`]) and its spin-up-path
//! section after Table 6 ([`paths`]), both reading
//! runs into the rows of [`rows`]. The searches that make its runs are generic and live in
//! [`crate::analysis::spinup_search`].

pub mod ladder;
pub mod paths;
pub mod report;
pub mod rows;
