//! Impact experiments on rubble-pile targets (Roig03 §3, Tables 1–2).
//!
//! - [`target`]: the Monte-Carlo rubble-pile builder and its relaxation to a rigidly rotating pile;
//! - [`projectile`]: the projectiles P1–P3 and the impact geometry.

pub mod projectile;
pub mod target;
