//! One finished frame: the bodies coloured by a [`ColourScale`] and ray-cast ([`render_frame`]), with a vertical
//! colour bar (label and end values, or category names) at the right edge and a caption at the top left.
//!
//! Text is drawn with plotters on the frame's own pixel buffer, in the embedded font the figures use, so frames
//! need no system fonts.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::analysis::figures::style::{FONT_FAMILY, ensure_font};
use crate::math::{Mat3, Vec3};

use super::camera::{BoundingSphere, Camera};
use super::colour::{ColourScale, ScaleKind};
use super::error::RenderError;
use super::image::RgbImage;
use super::overlay::{BAR_COLOUR, ScaleBar, Triad, draw_scale_bar};
use super::raycast::{RenderBody, render_scene};
use super::walls::WallPolygon;

/// Frame background: a dark blue-grey, so that both ends of viridis and the white text read on it.
pub const BACKGROUND: [u8; 3] = [24, 26, 34];
/// Colour of the caption and colour-bar text.
const TEXT_COLOUR: RGBColor = RGBColor(235, 235, 235);

/// One body of a frame: an ellipsoid and the scalar that colours it.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameBody {
    /// Centre (m).
    pub centre: Vec3,
    /// Rotation body → world (identity for a sphere).
    pub rotation: Mat3,
    /// Semi-axes A, B, C (m; equal for a sphere).
    pub axes: Vec3,
    /// The scalar drawn (speed, bound flag, …), in the unit of the scale.
    pub value: f64,
}

impl BoundingSphere for FrameBody {
    fn bounding_sphere(&self) -> (Vec3, f64) {
        (self.centre, self.axes.max())
    }
}

/// Renders one frame: `bodies` coloured by `scale` and ray-cast through `camera` on [`BACKGROUND`], then a colour
/// bar with the scale's label and range at the right edge, `caption` (e.g. "t = 123.4 s") at the top left, and at
/// the bottom left an axis triad and a scale bar ([`super::overlay`]).
pub fn render_frame(
    bodies: &[FrameBody],
    scale: &ColourScale,
    camera: &Camera,
    caption: &str,
) -> Result<RgbImage, RenderError> {
    render_frame_with_walls(bodies, &[], scale, camera, caption)
}

/// [`render_frame`] with translucent `walls` ([`super::walls`]) in the scene.
pub fn render_frame_with_walls(
    bodies: &[FrameBody],
    walls: &[WallPolygon],
    scale: &ColourScale,
    camera: &Camera,
    caption: &str,
) -> Result<RgbImage, RenderError> {
    let coloured: Vec<RenderBody> = bodies
        .iter()
        .map(|b| RenderBody {
            centre: b.centre,
            rotation: b.rotation,
            axes: b.axes,
            colour: scale.colour(b.value),
        })
        .collect();
    let mut image = render_scene(&coloured, walls, camera, BACKGROUND);
    let layout = Layout::new(image.width, image.height);
    draw_bar(&mut image, scale, &layout);
    let mut labels = Vec::new();
    let triad = layout.triad(camera);
    triad.draw(&mut image, f64::from(layout.line));
    for a in &triad.arrows {
        let (dx, dy) = (a.tip.0 - triad.origin.0, a.tip.1 - triad.origin.1);
        let len = dx.hypot(dy);
        // Beyond the tip, or beside the ring of an axis seen end-on.
        let ((ux, uy), reach) = if len < 0.25 * triad.length {
            ((0.7, -0.7), 0.45 * triad.length)
        } else {
            ((dx / len, dy / len), len + 0.6 * f64::from(layout.font))
        };
        let at = (triad.origin.0 + reach * ux, triad.origin.1 + reach * uy);
        labels.push((a.label.to_string(), (at.0 as i32, at.1 as i32), a.colour, VPos::Center));
    }
    if let Some(bar) = ScaleBar::for_camera(camera) {
        let (x0, y0) = layout.scale_bar_at();
        if x0 + bar.pixels < image.width.saturating_sub(layout.margin as u32) {
            draw_scale_bar(&mut image, &bar, x0, y0, layout.line);
            let centre = (x0 + bar.pixels / 2) as i32;
            // Above the end ticks, which rise one bar thickness.
            let above = y0 as i32 - 2 * layout.line as i32 - 2;
            labels.push((bar.label.clone(), (centre, above), BAR_COLOUR, VPos::Bottom));
        }
    }
    draw_text(&mut image, scale, &layout, caption, &labels)?;
    Ok(image)
}

/// A piece of text on a frame: what, where (pixels), its colour and its vertical anchor.
type Label = (String, (i32, i32), [u8; 3], VPos);

/// Sizes and places of the overlays, in pixels, scaled with the image.
struct Layout {
    margin: i32,
    font: u32,
    bar_x0: i32,
    bar_x1: i32,
    bar_y0: i32,
    bar_y1: i32,
    /// Thickness of the scale bar and the triad's shafts (pixels).
    line: u32,
    /// Image height (pixels).
    height: u32,
}

impl Layout {
    fn new(width: u32, height: u32) -> Layout {
        let (w, h) = (width as i32, height as i32);
        let short = w.min(h);
        let margin = (short / 50).max(6);
        let bar_width = (short / 40).max(8);
        let font = (short / 45).max(11) as u32;
        Layout {
            margin,
            font,
            bar_x0: w - margin - bar_width,
            bar_x1: w - margin,
            // Room above the bar for the label.
            bar_y0: h / 5,
            bar_y1: h - h / 5,
            line: (short / 200).max(2) as u32,
            height,
        }
    }

    /// Length of the triad's arrows and the distance of its foot from the left and bottom edges (pixels).
    fn triad_length_and_pad(&self) -> (f64, f64) {
        let len = f64::from(self.font) * 2.5;
        (len, f64::from(self.margin) + len + 1.2 * f64::from(self.font))
    }

    /// The triad in the bottom-left corner, room left for its labels.
    fn triad(&self, camera: &Camera) -> Triad {
        let (len, pad) = self.triad_length_and_pad();
        Triad::new(camera, (pad, f64::from(camera.height()) - pad), len)
    }

    /// Left end and top row of the scale bar: right of the triad, level with its foot.
    fn scale_bar_at(&self) -> (u32, u32) {
        let pad = self.triad_length_and_pad().1;
        (
            (2.0 * pad).round() as u32,
            (f64::from(self.height) - pad).round() as u32,
        )
    }
}

/// Fills the colour bar's pixels directly (no anti-aliasing wanted): top = max, bottom = min for a continuous
/// scale; one block per category, the first on top, for a categorical one.
fn draw_bar(image: &mut RgbImage, scale: &ColourScale, l: &Layout) {
    let (w, h) = (image.width as i32, image.height as i32);
    if l.bar_x0 < 0 || l.bar_y1 <= l.bar_y0 {
        return;
    }
    let span = f64::from(l.bar_y1 - l.bar_y0 - 1).max(1.0);
    for y in l.bar_y0.max(0)..l.bar_y1.min(h) {
        let colour = match &scale.kind {
            ScaleKind::Continuous { map, .. } => map.colour(1.0 - f64::from(y - l.bar_y0) / span),
            ScaleKind::Categorical(categories) if !categories.is_empty() => {
                let k = ((y - l.bar_y0) as usize * categories.len()) / (l.bar_y1 - l.bar_y0) as usize;
                categories[k.min(categories.len() - 1)].colour
            }
            ScaleKind::Categorical(_) => continue,
        };
        for x in l.bar_x0.max(0)..l.bar_x1.min(w) {
            image.set(x as u32, y as u32, colour);
        }
    }
}

/// Draws the caption and the colour bar's label and values with plotters on the image's own buffer.
/// `labels`: further text, each centred across its point, placed up and down by its `VPos`, in its colour (the
/// triad's and the scale bar's).
fn draw_text(
    image: &mut RgbImage,
    scale: &ColourScale,
    l: &Layout,
    caption: &str,
    labels: &[Label],
) -> Result<(), RenderError> {
    ensure_font().map_err(|e| RenderError::Text(e.to_string()))?;
    let text_err = |e: DrawingAreaErrorKind<_>| RenderError::Text(e.to_string());
    let (w, h) = (image.width, image.height);
    let root = BitMapBackend::with_buffer(&mut image.pixels, (w, h)).into_drawing_area();
    let style = |h_pos, v_pos| {
        TextStyle::from((FONT_FAMILY, l.font))
            .color(&TEXT_COLOUR)
            .pos(Pos::new(h_pos, v_pos))
    };
    if !caption.is_empty() {
        root.draw(&Text::new(caption, (l.margin, l.margin), style(HPos::Left, VPos::Top)))
            .map_err(text_err)?;
    }
    if !scale.label.is_empty() {
        root.draw(&Text::new(
            scale.label.as_str(),
            (l.bar_x1, l.bar_y0 - l.margin / 2),
            style(HPos::Right, VPos::Bottom),
        ))
        .map_err(text_err)?;
    }
    let ticks: Vec<(String, i32)> = match &scale.kind {
        ScaleKind::Continuous { min, max, .. } => {
            vec![(format_value(*max), l.bar_y0), (format_value(*min), l.bar_y1 - 1)]
        }
        ScaleKind::Categorical(categories) => {
            let block = (l.bar_y1 - l.bar_y0) / categories.len().max(1) as i32;
            let y = |k: usize| l.bar_y0 + block * k as i32 + block / 2;
            categories
                .iter()
                .enumerate()
                .map(|(k, c)| (c.name.clone(), y(k)))
                .collect()
        }
    };
    for (text, y) in ticks {
        let at = (l.bar_x0 - l.margin / 2, y);
        root.draw(&Text::new(text, at, style(HPos::Right, VPos::Center)))
            .map_err(text_err)?;
    }
    for (text, at, colour, v_pos) in labels {
        let rgb = RGBColor(colour[0], colour[1], colour[2]);
        let style = TextStyle::from((FONT_FAMILY, l.font))
            .color(&rgb)
            .pos(Pos::new(HPos::Center, *v_pos));
        root.draw(&Text::new(text.as_str(), *at, style)).map_err(text_err)?;
    }
    root.present().map_err(text_err)?;
    Ok(())
}

/// A bar end value in about three significant digits: plain for moderate magnitudes, scientific otherwise.
fn format_value(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".to_string()
    } else if !(1e-2..1e4).contains(&a) {
        format!("{v:.2e}")
    } else {
        let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
        let s = format!("{v:.decimals$}");
        // 1.50 → 1.5, 2.00 → 2: trailing zeros say nothing.
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    }
}

#[cfg(test)]
mod tests {
    use super::format_value;

    #[test]
    fn values_print_short() {
        assert_eq!(format_value(0.0), "0");
        assert_eq!(format_value(1.5), "1.5");
        assert_eq!(format_value(123.456), "123");
        assert_eq!(format_value(0.01234), "0.0123");
        assert_eq!(format_value(2.0), "2");
        assert_eq!(format_value(12345.0), "1.23e4");
    }
}
