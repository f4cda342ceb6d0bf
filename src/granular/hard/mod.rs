//! Hard-sphere discrete-element method after Richardson et al. (2011, Icarus 212, 427) ("Richardson11"): rigid
//! spheres with spin colliding instantaneously with normal and tangential restitution, walls made of primitives
//! ([`crate::geometry::walls`]), kick–drift–kick stepping with predicted collisions inside each drift (§2.1).
//!
//! [`particle`] (state), [`anchors`] (cell grid of the neighbour list), [`certificates`] (pair predictions kept
//! across steps), [`collision`] (resolution, ≈Eqs. 4–8, and the inelastic-collapse guard), [`events`] (priority
//! queue), [`stepper`] (the event loop), [`scene`] (`kind = "hard-spheres"`), [`run`] (the engine for the driver).
//!
//! Prediction (≈Eqs. 1–3): with `r = r_i − r_j`, `v = v_i − v_j`, `s = R_i + R_j`, the spheres touch at the earliest
//! root of `v² t² + 2(r·v) t + r² − s² = 0` while approaching (`r·v < 0`), computed without cancellation as
//! `t = (r² − s²)/(−r·v + √((r·v)² − v²(r² − s²)))`; a touching, approaching pair collides at once (`t ≤ 0`). Gravity
//! is uniform and acts in the kicks only, so drifts are straight lines; within a drift the earliest event is
//! processed and only its particles re-predicted. A uniform kick changes no relative velocity, so free pairs keep
//! their certificates across steps.

pub mod anchors;
pub mod certificates;
pub mod collision;
pub mod events;
pub mod particle;
pub mod run;
pub mod scene;
pub mod stepper;
