//! Hard-sphere discrete-element method after Richardson et al. (2011, Icarus 212, 427) ("Richardson11"):
//! rigid spheres with spin that collide instantaneously with normal and tangential restitution, walls made of
//! primitives ([`crate::geometry::walls`]), kick–drift–kick stepping with predicted collisions inside each drift.
//!
//! - [`particle`]: the sphere state;
//! - [`collision`]: collision resolution (particle–particle and particle–wall) and the inelastic-collapse guard;
//! - [`events`]: the priority queue of predicted collisions;
//! - [`stepper`]: the stepping and event loop;
//! - [`scene`]: the `kind = "hard-spheres"` scene file;
//! - [`run`]: the run driver (`rubblepile run`).

pub mod collision;
pub mod events;
pub mod particle;
pub mod run;
pub mod scene;
pub mod stepper;
