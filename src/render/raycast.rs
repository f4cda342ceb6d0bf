//! Exact ray casting of ellipsoids: the renderer ([`render_bodies`]) that shades every pixel by its nearest
//! ray–ellipsoid intersection.
//!
//! Cost: each body's bounding sphere is projected to a pixel rectangle first, and the bodies are bucketed by the
//! row bands their rectangles cover; a band (rendered in parallel with rayon) then tests only its own bodies, and
//! each of those only over the columns of its rectangle. So the work is the summed area of the rectangles, not
//! pixels × bodies.

use rayon::prelude::*;

use crate::math::{Mat3, Vec3};

use super::camera::ScreenBox;
use super::camera::{BoundingSphere, Camera, Ray};
use super::image::RgbImage;
pub use super::light::{AMBIENT, DIFFUSE, light_direction};
use super::walls::{WallPolygon, composite, wall_shade};

/// One body to draw: an ellipsoid with its colour.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderBody {
    /// Centre (m).
    pub centre: Vec3,
    /// Rotation body → world (orthonormal; identity for a sphere).
    pub rotation: Mat3,
    /// Semi-axes A, B, C along the body's x, y, z (m; equal for a sphere).
    pub axes: Vec3,
    /// Colour before shading.
    pub colour: [u8; 3],
}

impl BoundingSphere for RenderBody {
    fn bounding_sphere(&self) -> (Vec3, f64) {
        (self.centre, self.axes.max())
    }
}

/// An ellipsoid prepared for many rays: `to_unit = diag(1/axes)·Rᵀ` takes world offsets from the centre into the
/// frame where the ellipsoid is the unit sphere.
struct Prepared {
    centre: Vec3,
    rotation: Mat3,
    to_unit: Mat3,
    inv_axes: Vec3,
}

impl Prepared {
    fn new(centre: &Vec3, rotation: &Mat3, axes: &Vec3) -> Prepared {
        let inv_axes = axes.map(|a| 1.0 / a);
        Prepared {
            centre: *centre,
            rotation: *rotation,
            to_unit: Mat3::from_diagonal(&inv_axes) * rotation.transpose(),
            inv_axes,
        }
    }

    /// Nearest ray parameter `t > t_min` where the ray meets the surface, with the hit in unit-sphere coordinates.
    fn hit_t(&self, ray: &Ray, t_min: f64) -> Option<(f64, Vec3)> {
        let o = self.to_unit * (ray.origin - self.centre);
        let d = self.to_unit * ray.direction;
        // |o + t d|² = 1, in the half-b form: a t² + 2 h t + c = 0.
        let a = d.norm_squared();
        let h = o.dot(&d);
        let c = o.norm_squared() - 1.0;
        let disc = h * h - a * c;
        if disc < 0.0 || a == 0.0 {
            return None;
        }
        let sq = disc.sqrt();
        // The smaller root is the entry point; when it lies behind t_min the ray starts inside and the exit counts.
        let t = [(-h - sq) / a, (-h + sq) / a].into_iter().find(|t| *t > t_min)?;
        Some((t, o + t * d))
    }

    /// World-frame unit outward normal at the unit-sphere point `u`: the gradient of (p/axes)², i.e.
    /// R·(p_body/axes²) = R·(u/axes).
    fn normal(&self, u: &Vec3) -> Vec3 {
        (self.rotation * u.component_mul(&self.inv_axes)).normalize()
    }
}

/// Rows per band: bands are the unit of parallel work and of body bucketing. Small enough for load balance
/// over many threads, big enough that the per-band body lists stay short.
const BAND_ROWS: u32 = 8;

/// Renders `bodies` seen by `camera` on a `background`: each pixel takes the shaded colour of its nearest hit.
///
/// Shading: `colour · (0.25 + 0.75·max(0, n·l))` with `l` the [`light_direction`]. Parallel over row bands with
/// rayon's global pool.
pub fn render_bodies(bodies: &[RenderBody], camera: &Camera, background: [u8; 3]) -> RgbImage {
    render_scene(bodies, &[], camera, background)
}

/// Renders `bodies` as [`render_bodies`] does, seen through the translucent `walls` ([`super::walls`]): along each
/// pixel's ray the nearest body is opaque and every wall polygon crossed before it (or before the background)
/// blends over it with [`super::walls::WALL_ALPHA`].
pub fn render_scene(bodies: &[RenderBody], walls: &[WallPolygon], camera: &Camera, background: [u8; 3]) -> RgbImage {
    let (width, height) = (camera.width(), camera.height());
    let mut image = RgbImage::new(width, height, background);
    let light = light_direction(camera);
    let t_min = if camera.rays_are_lines() {
        f64::NEG_INFINITY
    } else {
        0.0
    };

    // Bodies with a usable shape and their pixel rectangles.
    let mut prepared = Vec::with_capacity(bodies.len());
    let mut boxes = Vec::with_capacity(bodies.len());
    for body in bodies {
        let ok = body.axes.iter().all(|a| a.is_finite() && *a > 0.0) && body.centre.iter().all(|c| c.is_finite());
        if !ok {
            continue;
        }
        if let Some(b) = camera.screen_box(&body.centre, body.axes.max()) {
            prepared.push((Prepared::new(&body.centre, &body.rotation, &body.axes), body.colour));
            boxes.push(b);
        }
    }

    // Which bodies each band must test.
    let n_bands = height.div_ceil(BAND_ROWS) as usize;
    let bands = bucket(&boxes, n_bands);
    // The walls on screen, bucketed the same way, each with its shading factor.
    let mut wall_boxes = Vec::new();
    let mut shown_walls = Vec::new();
    for w in walls {
        if let Some(b) = camera.screen_box_of_points(w.points()) {
            wall_boxes.push(b);
            shown_walls.push((w, wall_shade(camera, &w.normal())));
        }
    }
    let wall_bands = bucket(&wall_boxes, n_bands);
    // Two facets' hits this close along a ray are one crossing of their shared edge.
    let merge = 1e-9 * camera.framing().half_extent;

    let row_bytes = width as usize * 3;
    image
        .pixels
        .par_chunks_mut(BAND_ROWS as usize * row_bytes)
        .enumerate()
        .for_each(|(band, chunk)| {
            let members = &bands[band];
            let wall_members = &wall_bands[band];
            if members.is_empty() && wall_members.is_empty() {
                return;
            }
            let mut layers: Vec<(f64, f64)> = Vec::new();
            let mut depth = vec![f64::INFINITY; width as usize];
            let mut winner = vec![u32::MAX; width as usize];
            let mut unit_hit = vec![Vec3::zeros(); width as usize];
            for (r, row) in chunk.chunks_mut(row_bytes).enumerate() {
                let y = band as u32 * BAND_ROWS + r as u32;
                depth.fill(f64::INFINITY);
                winner.fill(u32::MAX);
                for &i in members {
                    let b = &boxes[i as usize];
                    if y < b.y0 || y > b.y1 {
                        continue;
                    }
                    let body = &prepared[i as usize].0;
                    for x in b.x0..=b.x1 {
                        let ray = camera.ray(x, y);
                        if let Some((t, u)) = body.hit_t(&ray, t_min) {
                            let xi = x as usize;
                            if t < depth[xi] {
                                depth[xi] = t;
                                winner[xi] = i;
                                unit_hit[xi] = u;
                            }
                        }
                    }
                }
                // Shade winners only: overdrawn hits cost no normal or lighting.
                for (xi, &w) in winner.iter().enumerate() {
                    let mut shaded = if w == u32::MAX {
                        background.map(f64::from)
                    } else {
                        let (body, colour) = &prepared[w as usize];
                        let n = body.normal(&unit_hit[xi]);
                        let k = AMBIENT + DIFFUSE * n.dot(&light).max(0.0);
                        colour.map(|c| f64::from(c) * k)
                    };
                    layers.clear();
                    // One ray per pixel, made only when some wall's rectangle holds the pixel.
                    let mut ray: Option<Ray> = None;
                    for &i in wall_members {
                        let b = &wall_boxes[i as usize];
                        if y < b.y0 || y > b.y1 || (xi as u32) < b.x0 || (xi as u32) > b.x1 {
                            continue;
                        }
                        let (wall, shade) = shown_walls[i as usize];
                        let ray = ray.get_or_insert_with(|| camera.ray(xi as u32, y));
                        if let Some(t) = wall.hit(ray, t_min)
                            && t < depth[xi]
                        {
                            layers.push((t, shade));
                        }
                    }
                    if w == u32::MAX && layers.is_empty() {
                        continue;
                    }
                    if !layers.is_empty() {
                        shaded = composite(shaded, &mut layers, merge);
                    }
                    for c in 0..3 {
                        row[xi * 3 + c] = shaded[c].round().clamp(0.0, 255.0) as u8;
                    }
                }
            }
        });
    image
}

/// For each of `n_bands` row bands, the indices of the `boxes` that reach into it.
fn bucket(boxes: &[ScreenBox], n_bands: usize) -> Vec<Vec<u32>> {
    let mut bands: Vec<Vec<u32>> = vec![Vec::new(); n_bands];
    for (i, b) in boxes.iter().enumerate() {
        for band in &mut bands[(b.y0 / BAND_ROWS) as usize..=(b.y1 / BAND_ROWS) as usize] {
            band.push(i as u32);
        }
    }
    bands
}
