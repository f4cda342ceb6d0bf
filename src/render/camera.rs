//! The camera: the direction a picture is taken from ([`View`]), orthographic or perspective ([`Projection`]), the
//! region of space it shows ([`Framing`]), and the primary ray through every pixel centre ([`Camera`]).
//!
//! Screen convention: pixel `(0, 0)` is the top-left corner, x grows to the right and y downwards; the camera's
//! `right` and `up` unit vectors are the world directions of screen right and screen up.

use std::fmt;
use std::str::FromStr;

use crate::math::Vec3;

use super::error::RenderError;

/// Direction a picture is taken from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// From +x looking toward −x; world z up on screen, world +y to the right.
    X,
    /// From +y looking toward −y; world z up on screen, world −x to the right.
    Y,
    /// From +z looking down toward −z; world y up on screen, world +x to the right.
    Z,
    /// From the direction (1, 1, 1) toward the origin; world z up on screen.
    Iso,
}

impl View {
    /// The camera basis `(forward, right, up)`: unit world vectors of the viewing direction (from the camera into
    /// the scene), screen right and screen up. Right-handed: `right = forward × up`.
    pub fn basis(self) -> (Vec3, Vec3, Vec3) {
        let (forward, up_hint) = match self {
            View::X => (-Vec3::x(), Vec3::z()),
            View::Y => (-Vec3::y(), Vec3::z()),
            View::Z => (-Vec3::z(), Vec3::y()),
            View::Iso => (-Vec3::new(1.0, 1.0, 1.0).normalize(), Vec3::z()),
        };
        let right = forward.cross(&up_hint).normalize();
        // Re-orthogonalised so the iso view's up is exactly perpendicular to its forward direction.
        let up = right.cross(&forward).normalize();
        (forward, right, up)
    }
}

impl FromStr for View {
    type Err = RenderError;

    /// Parses the `--view` names `x`, `y`, `z`, `iso` (case-insensitive).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let name = s.trim().to_ascii_lowercase();
        let all = [View::X, View::Y, View::Z, View::Iso];
        all.into_iter()
            .find(|v| v.to_string() == name)
            .ok_or_else(|| RenderError::UnknownView(s.to_string()))
    }
}

impl fmt::Display for View {
    /// The `--view` name (`x`, `y`, `z`, `iso`).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            View::X => "x",
            View::Y => "y",
            View::Z => "z",
            View::Iso => "iso",
        })
    }
}

/// How space is projected onto the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Parallel rays: sizes on screen do not depend on depth (what the measuring tests use).
    Orthographic,
    /// Rays from one eye point; `fov_deg` is the full field of view across the shorter image side (degrees,
    /// in (0, 180)).
    Perspective {
        /// Full field of view across the shorter image side (degrees).
        fov_deg: f64,
    },
}

/// Anything with a bounding sphere: what [`Framing::enclosing`] needs of a body.
pub trait BoundingSphere {
    /// Centre (m) and radius (m) of a sphere that contains the whole body.
    fn bounding_sphere(&self) -> (Vec3, f64);
}

/// The region of space a frame shows: a sphere of radius `half_extent` about `centre`. Orthographic frames span
/// ±`half_extent` across the shorter image side; perspective frames fit the sphere in the field of view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Framing {
    /// Centre of the picture (m).
    pub centre: Vec3,
    /// Half the width of the shorter image side, in world units (m).
    pub half_extent: f64,
}

impl Framing {
    /// Relative margin around the bodies, so the outermost ones do not touch the frame's edge.
    pub const MARGIN: f64 = 0.05;

    /// The framing of all `bodies`: centred on the smallest axis-aligned box around their bounding spheres, with
    /// `half_extent` the radius about that centre that holds every bounding sphere, plus 5 %.
    ///
    /// The radius (not the box's largest half-side) keeps every body in the picture from any [`View`], the iso one
    /// included, and for a roughly round pile it equals the pile's radius. Compute it once over all frames of a
    /// run (`frames.iter().flatten()`) so the camera does not jump between frames. No bodies give a 1 m framing
    /// about the origin.
    pub fn enclosing<'a, B, I>(bodies: I) -> Framing
    where
        B: BoundingSphere + 'a,
        I: IntoIterator<Item = &'a B>,
    {
        let spheres: Vec<(Vec3, f64)> = bodies.into_iter().map(|b| b.bounding_sphere()).collect();
        if spheres.is_empty() {
            return Framing {
                centre: Vec3::zeros(),
                half_extent: 1.0,
            };
        }
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        for (c, r) in &spheres {
            lo = lo.inf(&(c - Vec3::repeat(*r)));
            hi = hi.sup(&(c + Vec3::repeat(*r)));
        }
        let centre = 0.5 * (lo + hi);
        let radius = spheres.iter().map(|(c, r)| (c - centre).norm() + r).fold(0.0, f64::max);
        // A lone point body would give a zero-size frame and divide by zero in the camera.
        let half_extent = if radius > 0.0 && radius.is_finite() {
            radius * (1.0 + Self::MARGIN)
        } else {
            1.0
        };
        Framing { centre, half_extent }
    }
}

/// A ray: `origin + t·direction`, with `direction` a unit vector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point (m).
    pub origin: Vec3,
    /// Unit direction.
    pub direction: Vec3,
}

/// A pixel-space rectangle (inclusive bounds) that holds a body's projection.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ScreenBox {
    pub x0: u32,
    pub x1: u32,
    pub y0: u32,
    pub y1: u32,
}

/// A camera: image size, basis and projection; gives the primary ray of each pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    projection: Projection,
    framing: Framing,
    width: u32,
    height: u32,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    /// Pixels per unit of screen coordinate: screen coordinates run over [−1, 1] across the shorter side.
    half_short_px: f64,
    /// Orthographic: metres per unit screen coordinate (`half_extent`); perspective: tan(fov/2).
    scale: f64,
    /// Perspective eye point (m); for orthographic views the plane rays start from passes through it.
    eye: Vec3,
}

impl Camera {
    /// A camera looking along `view` at `framing`, for an image of `width_px × height_px` pixels (each ≥ 1).
    ///
    /// Orthographic: parallel rays, starting on a plane `2·half_extent` in front of the framing centre, spanning
    /// ±`half_extent` across the shorter side. Perspective: the eye sits at distance `half_extent / sin(fov/2)`
    /// from the centre, so the framing sphere just fits the field of view. Perspective field of view is clamped
    /// to [1°, 170°].
    pub fn new(view: View, projection: Projection, framing: Framing, width_px: u32, height_px: u32) -> Camera {
        let (forward, right, up) = view.basis();
        let width = width_px.max(1);
        let height = height_px.max(1);
        let half_short_px = 0.5 * f64::from(width.min(height));
        let (scale, eye) = match projection {
            Projection::Orthographic => (
                framing.half_extent,
                framing.centre - 2.0 * framing.half_extent * forward,
            ),
            Projection::Perspective { fov_deg } => {
                let half = 0.5 * fov_deg.clamp(1.0, 170.0).to_radians();
                let distance = framing.half_extent / half.sin();
                (half.tan(), framing.centre - distance * forward)
            }
        };
        Camera {
            projection,
            framing,
            width,
            height,
            forward,
            right,
            up,
            half_short_px,
            scale,
            eye,
        }
    }

    /// Image width (pixels).
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Image height (pixels).
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The framing this camera was built with.
    pub fn framing(&self) -> Framing {
        self.framing
    }

    /// Unit viewing direction (from the camera into the scene).
    pub fn forward(&self) -> Vec3 {
        self.forward
    }

    /// Unit world direction of screen right.
    pub fn right(&self) -> Vec3 {
        self.right
    }

    /// Unit world direction of screen up.
    pub fn up(&self) -> Vec3 {
        self.up
    }

    /// Pixels per metre at the depth of the framing centre: the orthographic scale, or for a perspective camera the
    /// scale of the plane through the framing centre facing the camera (nearer things look bigger, farther smaller).
    pub fn pixels_per_metre_at_centre(&self) -> f64 {
        match self.projection {
            Projection::Orthographic => self.half_short_px / self.scale,
            Projection::Perspective { .. } => {
                let depth = (self.framing.centre - self.eye).dot(&self.forward);
                self.half_short_px / (self.scale * depth)
            }
        }
    }

    /// Where the world point `p` (m) lands on the image: fractional pixel coordinates `(x, y)` of the pixel grid
    /// (`(0.5, 0.5)` is the centre of the top-left pixel, y down), or `None` for a point at or behind a perspective
    /// eye. The inverse of [`Camera::ray`]: the ray of pixel `(i, j)` passes through points that project to
    /// `(i + 0.5, j + 0.5)`.
    pub fn project(&self, p: &Vec3) -> Option<(f64, f64)> {
        let d = p - self.eye;
        let (cx, cy) = (d.dot(&self.right), d.dot(&self.up));
        let (sx, sy) = match self.projection {
            Projection::Orthographic => (cx / self.scale, cy / self.scale),
            Projection::Perspective { .. } => {
                let cz = d.dot(&self.forward);
                if cz <= 0.0 {
                    return None;
                }
                (cx / (cz * self.scale), cy / (cz * self.scale))
            }
        };
        Some((
            0.5 * f64::from(self.width) + sx * self.half_short_px,
            0.5 * f64::from(self.height) - sy * self.half_short_px,
        ))
    }

    /// Whether rays are lines rather than half-lines: orthographic rays start on an arbitrary plane, so a body
    /// behind that plane is still seen (the nearest intersection along the whole line counts).
    pub(crate) fn rays_are_lines(&self) -> bool {
        matches!(self.projection, Projection::Orthographic)
    }

    /// Screen coordinates (each in [−1, 1] across the shorter side, y up) of the centre of pixel `(x, y)`.
    #[inline]
    fn screen(&self, x: f64, y: f64) -> (f64, f64) {
        let sx = (x + 0.5 - 0.5 * f64::from(self.width)) / self.half_short_px;
        let sy = (0.5 * f64::from(self.height) - (y + 0.5)) / self.half_short_px;
        (sx, sy)
    }

    /// The primary ray through the centre of pixel `(x, y)` (`(0, 0)` = top left). Inlined: the renderer's inner
    /// loop asks it of every pixel of every body's rectangle, and a call there costs as much as the ray itself.
    #[inline]
    pub fn ray(&self, x: u32, y: u32) -> Ray {
        let (sx, sy) = self.screen(f64::from(x), f64::from(y));
        match self.projection {
            Projection::Orthographic => Ray {
                origin: self.eye + self.scale * (sx * self.right + sy * self.up),
                direction: self.forward,
            },
            Projection::Perspective { .. } => Ray {
                origin: self.eye,
                direction: (self.forward + self.scale * (sx * self.right + sy * self.up)).normalize(),
            },
        }
    }

    /// The pixel rectangle that holds the projection of the convex polygon through `points` (m), with one pixel of
    /// slack; `None` when it is wholly off screen or behind a perspective eye. A perspective camera sees only the
    /// part in front of its eye: the polygon is clipped to depths of at least a billionth of the framing's
    /// half-width first (Sutherland & Hodgman 1974, against one plane), so a wall reaching past the eye keeps a
    /// bounded rectangle.
    pub(crate) fn screen_box_of_points(&self, points: &[Vec3]) -> Option<ScreenBox> {
        let clipped;
        let points = match self.projection {
            Projection::Orthographic => points,
            Projection::Perspective { .. } => {
                let near = 1e-9 * self.framing.half_extent;
                let depth = |p: &Vec3| (p - self.eye).dot(&self.forward) - near;
                if points.iter().all(|p| depth(p) > 0.0) {
                    points
                } else {
                    let mut kept = Vec::with_capacity(points.len() + 1);
                    for (k, a) in points.iter().enumerate() {
                        let b = &points[(k + 1) % points.len()];
                        let (da, db) = (depth(a), depth(b));
                        if da > 0.0 {
                            kept.push(*a);
                        }
                        if (da > 0.0) != (db > 0.0) {
                            // Where the edge crosses the near plane, nudged to its front side.
                            let s = (da / (da - db)).clamp(0.0, 1.0);
                            let cross = a + s * (b - a);
                            kept.push(cross + (near - (cross - self.eye).dot(&self.forward)).max(0.0) * self.forward);
                        }
                    }
                    clipped = kept;
                    &clipped
                }
            }
        };
        let mut lo = (f64::INFINITY, f64::INFINITY);
        let mut hi = (f64::NEG_INFINITY, f64::NEG_INFINITY);
        for p in points {
            let (x, y) = self.project(p)?;
            lo = (lo.0.min(x), lo.1.min(y));
            hi = (hi.0.max(x), hi.1.max(y));
        }
        if points.is_empty() {
            return None;
        }
        let (x0, x1) = pixel_span(lo.0, hi.0, self.width, false)?;
        let (y0, y1) = pixel_span(lo.1, hi.1, self.height, false)?;
        Some(ScreenBox { x0, x1, y0, y1 })
    }

    /// The pixel rectangle that holds the projection of the sphere (`centre`, `radius`), or `None` when the sphere
    /// is wholly off screen (or behind a perspective eye).
    pub(crate) fn screen_box(&self, centre: &Vec3, radius: f64) -> Option<ScreenBox> {
        let full = ScreenBox {
            x0: 0,
            x1: self.width - 1,
            y0: 0,
            y1: self.height - 1,
        };
        let d = centre - self.eye;
        let (cx, cy, cz) = (d.dot(&self.right), d.dot(&self.up), d.dot(&self.forward));
        let ((x_lo, x_hi), (y_lo, y_hi)) = match self.projection {
            Projection::Orthographic => {
                let (sx, sy, sr) = (cx / self.scale, cy / self.scale, radius / self.scale);
                ((sx - sr, sx + sr), (sy - sr, sy + sr))
            }
            Projection::Perspective { .. } => {
                if cz + radius <= 0.0 {
                    return None;
                }
                // Exact tangent bounds per axis: in the (lateral, depth) plane the sphere subtends the angles
                // θc ± α about the eye, α = asin(r/dist). A sphere too near the eye for that to stay within ±90°
                // may cover anything, so it gets the whole screen.
                let bounds = |lateral: f64| -> Option<(f64, f64)> {
                    let dist = lateral.hypot(cz);
                    if radius >= dist {
                        return None;
                    }
                    let theta = lateral.atan2(cz);
                    let alpha = (radius / dist).asin();
                    let limit = std::f64::consts::FRAC_PI_2 - 1e-6;
                    if (theta - alpha) <= -limit || (theta + alpha) >= limit {
                        return None;
                    }
                    Some(((theta - alpha).tan() / self.scale, (theta + alpha).tan() / self.scale))
                };
                match (bounds(cx), bounds(cy)) {
                    (Some(bx), Some(by)) => (bx, by),
                    _ => return Some(full),
                }
            }
        };
        // Screen y is up, pixel y is down: the y range flips.
        let (cx, cy, k) = (
            0.5 * f64::from(self.width),
            0.5 * f64::from(self.height),
            self.half_short_px,
        );
        let (x0, x1) = pixel_span(cx + x_lo * k, cx + x_hi * k, self.width, true)?;
        let (y0, y1) = pixel_span(cy - y_hi * k, cy - y_lo * k, self.height, true)?;
        Some(ScreenBox { x0, x1, y0, y1 })
    }
}

/// Inclusive bounds of the pixels (pixel k covers [k, k + 1)) of a side of `n` whose centres the fractional pixel
/// range [`lo`, `hi`] may cover, with one pixel of slack so that rounding never drops a covered pixel; `None` when
/// it misses the image, is NaN, or (`finite`) reaches infinity.
fn pixel_span(lo: f64, hi: f64, n: u32, finite: bool) -> Option<(u32, u32)> {
    let (a, b) = ((lo - 1.0).floor(), (hi + 1.0).ceil());
    let bad = if finite {
        !(a.is_finite() && b.is_finite())
    } else {
        a.is_nan() || b.is_nan()
    };
    if bad || b < 0.0 || a > f64::from(n - 1) {
        return None;
    }
    Some((a.max(0.0) as u32, b.min(f64::from(n - 1)) as u32))
}
