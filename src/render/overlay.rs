//! What every frame carries besides the bodies to be read as a measurement: a scale bar ([`ScaleBar`]: a round
//! length of 1, 2 or 5 × 10^k m, about a fifth of the frame wide, with its label) and an axis triad ([`Triad`]: the
//! world x, y and z directions as the camera sees them, each a labelled arrow).
//!
//! Both are filled pixel by pixel (no anti-aliasing), so a test can measure them; their labels are drawn with the
//! frame's text (by `render::frame`, which places these marks). The conventions are those of map and microscope scale
//! bars and of CAD view triads (x red, y green, z blue).

use crate::math::Vec3;

use super::camera::Camera;
use super::image::RgbImage;

/// Colour of the x arrow.
pub const X_COLOUR: [u8; 3] = [235, 85, 75];
/// Colour of the y arrow.
pub const Y_COLOUR: [u8; 3] = [95, 205, 95];
/// Colour of the z arrow.
pub const Z_COLOUR: [u8; 3] = [90, 150, 245];
/// Colour of the scale bar (the frame's text colour).
pub const BAR_COLOUR: [u8; 3] = [235, 235, 235];

/// A scale bar: a round length and how many pixels it spans.
#[derive(Clone, Debug, PartialEq)]
pub struct ScaleBar {
    /// Length it stands for (m): 1, 2 or 5 × 10^k.
    pub metres: f64,
    /// Length on the image (pixels): `metres` × the camera's pixels per metre, rounded.
    pub pixels: u32,
    /// Its label, e.g. "500 m", "20 km", "5 mm".
    pub label: String,
}

impl ScaleBar {
    /// The bar for `camera`: of the lengths 1, 2, 5 × 10^k m, the one nearest (in ratio) to a fifth of the image
    /// width, at the camera's scale at the framing centre ([`Camera::pixels_per_metre_at_centre`]; a perspective
    /// picture's scale holds at that depth only). `None` for a camera without a finite scale.
    pub fn for_camera(camera: &Camera) -> Option<ScaleBar> {
        let ppm = camera.pixels_per_metre_at_centre();
        let wanted = f64::from(camera.width()) / 5.0 / ppm;
        if !(wanted.is_finite() && wanted > 0.0) {
            return None;
        }
        let decade = 10f64.powf(wanted.log10().floor());
        let metres = [1.0, 2.0, 5.0, 10.0]
            .into_iter()
            .map(|m| m * decade)
            .min_by(|a, b| (a / wanted).ln().abs().total_cmp(&(b / wanted).ln().abs()))?;
        Some(ScaleBar {
            metres,
            pixels: (metres * ppm).round() as u32,
            label: length_label(metres),
        })
    }
}

/// A round length with its unit: km from 1 km, m from 1 m, mm below (scientific below 1 mm).
pub fn length_label(metres: f64) -> String {
    // Six significant digits at most, so 0.2 × 10³ prints as 200, not 200.00000000000003.
    let short = |v: f64| {
        let s = format!("{:.6}", v);
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    if metres >= 1e3 {
        format!("{} km", short(metres / 1e3))
    } else if metres >= 1.0 {
        format!("{} m", short(metres))
    } else if metres >= 1e-3 {
        format!("{} mm", short(metres * 1e3))
    } else {
        format!("{metres:.0e} m")
    }
}

/// One arrow of the triad.
#[derive(Clone, Debug, PartialEq)]
pub struct Arrow {
    /// "x", "y" or "z".
    pub label: &'static str,
    /// Its colour.
    pub colour: [u8; 3],
    /// The tip (fractional pixel coordinates, y down); equal to the triad's origin for an axis along the view.
    pub tip: (f64, f64),
    /// The world axis' component along the viewing direction: < 0 towards the viewer.
    pub depth: f64,
}

/// The axis triad: where it sits and its three arrows.
#[derive(Clone, Debug, PartialEq)]
pub struct Triad {
    /// Common foot of the arrows (fractional pixel coordinates, y down).
    pub origin: (f64, f64),
    /// Length of an arrow lying in the image plane (pixels).
    pub length: f64,
    /// The x, y and z arrows, in that order.
    pub arrows: [Arrow; 3],
}

impl Triad {
    /// The triad of `camera` with its foot at `origin` and arrows of `length` pixels: world axis `e` is drawn from
    /// the foot along (e·right, −e·up)·length, its projection on the image plane (y down on the image). Perspective
    /// cameras use the same directions (those at the image centre).
    pub fn new(camera: &Camera, origin: (f64, f64), length: f64) -> Triad {
        let arrow = |label, colour, e: Vec3| Arrow {
            label,
            colour,
            tip: (
                origin.0 + length * e.dot(&camera.right()),
                origin.1 - length * e.dot(&camera.up()),
            ),
            depth: e.dot(&camera.forward()),
        };
        Triad {
            origin,
            length,
            arrows: [
                arrow("x", X_COLOUR, Vec3::x()),
                arrow("y", Y_COLOUR, Vec3::y()),
                arrow("z", Z_COLOUR, Vec3::z()),
            ],
        }
    }

    /// Draws the arrows, farthest first so a nearer one lies on top: a shaft of `thickness` pixels and a head; an
    /// axis seen end-on (shorter than a quarter of the length on screen) as a ring about the foot, dotted when it
    /// points at the viewer and crossed when it points away.
    pub fn draw(&self, image: &mut RgbImage, thickness: f64) {
        let mut order: Vec<&Arrow> = self.arrows.iter().collect();
        order.sort_by(|a, b| b.depth.total_cmp(&a.depth));
        for a in order {
            let (dx, dy) = (a.tip.0 - self.origin.0, a.tip.1 - self.origin.1);
            let len = dx.hypot(dy);
            if len < 0.25 * self.length {
                // Seen end-on: a ring, with a dot in it when the axis points at the viewer (⊙) and a cross when it
                // points away (⊗), as field lines are drawn.
                let r = 0.25 * self.length;
                let (ox, oy) = self.origin;
                let towards = a.depth < 0.0;
                fill(image, a.colour, self.origin, r + thickness, |x, y| {
                    let (px, py) = (x - ox, y - oy);
                    let ring = (px.hypot(py) - r).abs() <= 0.5 * thickness;
                    let mark = if towards {
                        px.hypot(py) <= thickness
                    } else {
                        px.hypot(py) <= r && ((px - py).abs().min((px + py).abs()) <= 0.5 * thickness * 1.5)
                    };
                    ring || mark
                });
                continue;
            }
            let (ux, uy) = (dx / len, dy / len);
            let head = (3.0 * thickness).max(0.25 * len);
            fill(image, a.colour, self.origin, len, |x, y| {
                let (px, py) = (x - self.origin.0, y - self.origin.1);
                let along = px * ux + py * uy;
                let across = (px * uy - py * ux).abs();
                // The shaft up to the head's base, then a head tapering from 1.5 shaft widths on each side to the tip.
                if along < 0.0 || along > len {
                    return false;
                }
                if along <= len - head {
                    across <= 0.5 * thickness
                } else {
                    across <= 1.5 * thickness * (len - along) / head
                }
            });
        }
    }
}

/// Sets to `colour` every pixel whose centre lies within `reach` of `centre` and satisfies `inside`.
fn fill(image: &mut RgbImage, colour: [u8; 3], centre: (f64, f64), reach: f64, inside: impl Fn(f64, f64) -> bool) {
    let (w, h) = (f64::from(image.width), f64::from(image.height));
    let x0 = (centre.0 - reach - 1.0).floor().max(0.0);
    let x1 = (centre.0 + reach + 1.0).ceil().min(w - 1.0);
    let y0 = (centre.1 - reach - 1.0).floor().max(0.0);
    let y1 = (centre.1 + reach + 1.0).ceil().min(h - 1.0);
    if x1 < x0 || y1 < y0 {
        return;
    }
    for y in y0 as u32..=y1 as u32 {
        for x in x0 as u32..=x1 as u32 {
            if inside(f64::from(x) + 0.5, f64::from(y) + 0.5) {
                image.set(x, y, colour);
            }
        }
    }
}

/// Draws `bar` with its left end at pixel column `x0` and its top row at `y0`, `thickness` rows thick, with end
/// ticks rising `thickness` rows above it (the ticks are one bar-thickness wide, inside the bar's length).
pub fn draw_scale_bar(image: &mut RgbImage, bar: &ScaleBar, x0: u32, y0: u32, thickness: u32) {
    let (w, h) = (image.width, image.height);
    let x1 = (x0 + bar.pixels).min(w);
    for y in y0..(y0 + thickness).min(h) {
        for x in x0..x1 {
            image.set(x, y, BAR_COLOUR);
        }
    }
    let tick_w = thickness.min(bar.pixels / 2).max(1);
    for y in y0.saturating_sub(thickness)..y0.min(h) {
        for x in (x0..(x0 + tick_w).min(x1)).chain(x1.saturating_sub(tick_w).max(x0)..x1) {
            image.set(x, y, BAR_COLOUR);
        }
    }
}
