//! Granular engines: spheres with contacts.

pub mod hard;
