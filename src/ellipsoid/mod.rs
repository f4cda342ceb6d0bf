//! The interacting-ellipsoids model (Roig03 §2).
//!
//! - [`body`]: shape, mass, moments of inertia;
//! - [`quaternion`]: `R(q)` (Eq. 21), `W(q)` (Eq. 24) and their derivatives;
//! - [`potential`]: the Gaussian-overlap contact potential (Eqs. 7–12) and its gradients;
//! - [`calibration`]: κ from Eq. 14 and `U0` from Eq. 11;
//! - [`gravity`]: monopole gravity (Eq. 6);
//! - [`dissipation`]: the point dissipation function (Eqs. 40–41);
//! - [`barrier`]: the contact-barrier overrun detector (calibration of Eqs. 13–14 checked during a run);
//! - [`equations`]: the equations of motion (Eqs. 28–37) as an [`crate::integrate::OdeSystem`].

pub mod barrier;
pub mod body;
pub mod calibration;
pub mod cloud;
pub mod dissipation;
pub mod equations;
pub mod gravity;
pub mod output;
pub mod potential;
pub mod quaternion;
pub mod rigid_rotation;
pub mod run;
pub mod scene;
pub mod summary;
