//! Granular engines: rubble piles as collections of spheres. [`soft`] is the soft-sphere discrete element
//! method (SSDEM) of Zhang et al. (2017, Icarus 294) ("Zhang17"), with the rotational resistance of their §2.2;
//! [`hard`] the hard-sphere method with predicted collisions of Richardson et al. (2011, Icarus 212). Their scene
//! files share one [`vocabulary`]; [`migrate`] reads and rewrites the old names.

pub mod hard;
pub mod migrate;
pub mod soft;
pub mod vocabulary;
