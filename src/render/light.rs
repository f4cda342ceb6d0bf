//! The one light of every picture: its direction (from the upper left, in front of the scene) and the ambient and
//! diffuse shares of the Lambert shading (Lambert's cosine law, as in any ray tracer), used alike by the bodies
//! (`raycast`) and the translucent walls (`walls`).

use super::camera::Camera;
use crate::math::Vec3;

/// Ambient share of the light: faces turned away from the light still show their colour at this fraction.
pub const AMBIENT: f64 = 0.25;
/// Diffuse share of the light (ambient + diffuse = 1, so a face turned to the light shows its full colour).
pub const DIFFUSE: f64 = 0.75;

/// The unit direction towards the light of `camera`'s pictures: from the upper left, in front of the scene (camera
/// space), so shapes and orientations read well whatever the view.
pub fn light_direction(camera: &Camera) -> Vec3 {
    (-camera.right() + camera.up() - 1.2 * camera.forward()).normalize()
}
