//! Granular engines: rubble piles as collections of spheres. [`soft`] is the soft-sphere discrete element
//! method (SSDEM) of Zhang et al. (2017, Icarus 294) ("Zhang17"), with the rotational resistance of their §2.2.

pub mod soft;
