//! The render layer: ray-cast ellipsoids measured against their analytic projections, depth order, the `--view`
//! parser, full frames, and PNG / GIF files read back with their decoders.

use std::path::PathBuf;
use std::str::FromStr;

use rubblepile::math::{Mat3, Vec3};
use rubblepile::render::{
    Camera, ColourScale, FrameBody, Framing, GifWriter, Projection, RenderBody, RgbImage, View, render_bodies,
    render_frame, write_png,
};

const BG: [u8; 3] = [0, 0, 0];
const SIZE: u32 = 400;
/// Framing half-extent (m): with a 400 px image, 40 px per metre.
const HALF: f64 = 5.0;

fn ortho(view: View) -> Camera {
    let framing = Framing {
        centre: Vec3::zeros(),
        half_extent: HALF,
    };
    Camera::new(view, Projection::Orthographic, framing, SIZE, SIZE)
}

/// Covered pixels: their count, the centroid of their centres (pixel units, x right, y down) and their bounding
/// box `(x_min, x_max, y_min, y_max)`.
fn coverage(image: &RgbImage) -> (usize, (f64, f64), (u32, u32, u32, u32)) {
    let (mut n, mut sx, mut sy) = (0usize, 0.0, 0.0);
    let mut bbox = (u32::MAX, 0, u32::MAX, 0);
    for y in 0..image.height {
        for x in 0..image.width {
            if image.get(x, y) != BG {
                n += 1;
                sx += f64::from(x) + 0.5;
                sy += f64::from(y) + 0.5;
                bbox = (bbox.0.min(x), bbox.1.max(x), bbox.2.min(y), bbox.3.max(y));
            }
        }
    }
    (n, (sx / n as f64, sy / n as f64), bbox)
}

fn body(centre: Vec3, rotation: Mat3, axes: Vec3, colour: [u8; 3]) -> RenderBody {
    RenderBody {
        centre,
        rotation,
        axes,
        colour,
    }
}

#[test]
fn ellipsoid_projects_to_its_analytic_ellipse_along_each_axis() {
    let centre = Vec3::new(0.7, -1.1, 0.4);
    let axes = Vec3::new(3.0, 2.0, 1.0);
    let ppm = f64::from(SIZE) / (2.0 * HALF);
    let mid = 0.5 * f64::from(SIZE);
    // (view, screen semi-axes a (x) and b (y) in m, expected centre in pixels).
    let cases = [
        // From +x: screen right = +y, up = +z → the B×C ellipse.
        (View::X, 2.0, 1.0, (mid + centre.y * ppm, mid - centre.z * ppm)),
        // From +y: screen right = −x, up = +z → A×C.
        (View::Y, 3.0, 1.0, (mid - centre.x * ppm, mid - centre.z * ppm)),
        // From +z: screen right = +x, up = +y → A×B.
        (View::Z, 3.0, 2.0, (mid + centre.x * ppm, mid - centre.y * ppm)),
    ];
    for (view, a, b, (cx, cy)) in cases {
        let camera = ortho(view);
        assert_eq!(camera.pixels_per_metre_at_centre(), ppm);
        let image = render_bodies(&[body(centre, Mat3::identity(), axes, [200, 180, 160])], &camera, BG);
        let (n, (mx, my), (x0, x1, y0, y1)) = coverage(&image);
        let area = std::f64::consts::PI * a * b * ppm * ppm;
        let rel = (n as f64 - area).abs() / area;
        assert!(
            rel < 0.02,
            "{view}: {n} px covered, analytic {area:.0} px ({:.2} %)",
            100.0 * rel
        );
        assert!(
            (mx - cx).abs() < 1.0 && (my - cy).abs() < 1.0,
            "{view}: centroid ({mx:.2}, {my:.2}) vs ({cx}, {cy})"
        );
        // Orientation: the extents follow the screen semi-axes.
        let (wx, wy) = (f64::from(x1 - x0 + 1), f64::from(y1 - y0 + 1));
        assert!(
            (wx - 2.0 * a * ppm).abs() <= 2.0,
            "{view}: width {wx} px, expected {}",
            2.0 * a * ppm
        );
        assert!(
            (wy - 2.0 * b * ppm).abs() <= 2.0,
            "{view}: height {wy} px, expected {}",
            2.0 * b * ppm
        );
        for (x, y) in [(0, 0), (SIZE - 1, 0), (0, SIZE - 1), (SIZE - 1, SIZE - 1)] {
            assert_eq!(image.get(x, y), BG, "{view}: corner ({x}, {y}) drawn on");
        }
    }
}

#[test]
fn rotated_ellipsoid_turns_its_long_side_on_screen() {
    // 90° about z: body x (A = 3 m) lies along world y, which is screen up for View::Z.
    let rotation = Mat3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
    let axes = Vec3::new(3.0, 2.0, 1.0);
    let ppm = f64::from(SIZE) / (2.0 * HALF);
    let image = render_bodies(
        &[body(Vec3::zeros(), rotation, axes, [255, 255, 255])],
        &ortho(View::Z),
        BG,
    );
    let (n, (mx, my), (x0, x1, y0, y1)) = coverage(&image);
    let area = std::f64::consts::PI * 3.0 * 2.0 * ppm * ppm;
    assert!((n as f64 - area).abs() / area < 0.02, "{n} px vs {area:.0}");
    assert!((mx - 200.0).abs() < 1.0 && (my - 200.0).abs() < 1.0);
    let (wx, wy) = (f64::from(x1 - x0 + 1), f64::from(y1 - y0 + 1));
    assert!((wx - 2.0 * 2.0 * ppm).abs() <= 2.0, "width {wx}");
    assert!((wy - 2.0 * 3.0 * ppm).abs() <= 2.0, "height {wy}");
}

#[test]
fn nearer_body_wins_whatever_the_order() {
    let red = [250, 0, 0];
    let green = [0, 250, 0];
    let big = body(Vec3::zeros(), Mat3::identity(), Vec3::repeat(2.0), red);
    // In front of the big sphere as seen from +z, off its centre line.
    let small_centre = Vec3::new(0.5, -0.5, 2.3);
    let small = body(small_centre, Mat3::identity(), Vec3::repeat(0.4), green);
    let framing = Framing {
        centre: Vec3::zeros(),
        half_extent: HALF,
    };
    for projection in [Projection::Orthographic, Projection::Perspective { fov_deg: 40.0 }] {
        let camera = Camera::new(View::Z, projection, framing, SIZE, SIZE);
        // The small sphere's centre pixel: for perspective, where its centre's direction from the eye meets the
        // screen; with the eye on the z axis that is the centre scaled by the depth ratio.
        let eye_distance = HALF / (20.0f64).to_radians().sin();
        let (px, py) = match projection {
            Projection::Orthographic => (200.0 + 0.5 * 40.0, 200.0 + 0.5 * 40.0),
            Projection::Perspective { .. } => {
                let depth = eye_distance - small_centre.z;
                let tan_half = (20.0f64).to_radians().tan();
                let s = 0.5 / depth / tan_half * 200.0;
                (200.0 + s, 200.0 + s)
            }
        };
        for bodies in [vec![big.clone(), small.clone()], vec![small.clone(), big.clone()]] {
            let image = render_bodies(&bodies, &camera, BG);
            let c = image.get(px as u32, py as u32);
            assert!(
                c[1] > 0 && c[0] == 0,
                "{projection:?}: centre pixel {c:?} is not the small green sphere"
            );
            // And the big sphere shows around it.
            let c = image.get(200 - 40, 200);
            assert!(c[0] > 0 && c[1] == 0, "{projection:?}: big sphere missing: {c:?}");
        }
    }
}

#[test]
fn unknown_view_names_the_option() {
    let err = View::from_str("q").unwrap_err().to_string();
    assert!(err.contains("--view"), "{err}");
    assert!(err.contains("iso"), "{err}");
    for (s, v) in [("x", View::X), ("y", View::Y), ("z", View::Z), ("iso", View::Iso)] {
        assert_eq!(View::from_str(s).unwrap(), v);
        assert_eq!(v.to_string(), s);
    }
}

#[test]
fn framing_encloses_all_bodies_with_margin() {
    let bodies = [
        FrameBody {
            centre: Vec3::new(-4.0, 0.0, 0.0),
            rotation: Mat3::identity(),
            axes: Vec3::new(1.0, 0.5, 0.5),
            value: 0.0,
        },
        FrameBody {
            centre: Vec3::new(6.0, 0.0, 0.0),
            rotation: Mat3::identity(),
            axes: Vec3::repeat(1.0),
            value: 1.0,
        },
    ];
    let framing = Framing::enclosing(bodies.iter());
    assert!((framing.centre - Vec3::new(1.0, 0.0, 0.0)).norm() < 1e-12);
    assert!((framing.half_extent - 6.0 * 1.05).abs() < 1e-12);
    // Every body lies inside the iso view too.
    let camera = Camera::new(View::Iso, Projection::Orthographic, framing, 300, 200);
    let scale = ColourScale::new("v (m/s)", 0.0, 1.0);
    let image = render_frame(&bodies, &scale, &camera, "").unwrap();
    assert_eq!((image.width, image.height), (300, 200));
}

#[test]
fn frame_has_caption_and_colour_bar() {
    let bodies = [FrameBody {
        centre: Vec3::zeros(),
        rotation: Mat3::identity(),
        axes: Vec3::repeat(1.0),
        value: 0.5,
    }];
    let camera = ortho(View::Iso);
    let plain = render_bodies(&[], &camera, rubblepile::render::BACKGROUND);
    for scale in [
        ColourScale::new("speed (m/s)", 0.0, 2.0),
        ColourScale::categorical("state", vec![(1.0, "bound".into()), (0.0, "free".into())]),
    ] {
        let image = render_frame(&bodies, &scale, &camera, "t = 123.4 s").unwrap();
        let changed = |x0: u32, x1: u32, y0: u32, y1: u32| {
            (y0..y1)
                .flat_map(|y| (x0..x1).map(move |x| (x, y)))
                .filter(|&(x, y)| image.get(x, y) != plain.get(x, y))
                .count()
        };
        assert!(changed(0, 150, 0, 40) > 50, "no caption drawn");
        assert!(changed(370, 400, 100, 300) > 1000, "no colour bar drawn");
        // The body is coloured by its value (not background) at the centre.
        assert_ne!(image.get(200, 200), plain.get(200, 200));
    }
}

fn scratch(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("render-test-{name}"))
}

fn test_frame(shift: f64) -> RgbImage {
    let bodies = [FrameBody {
        centre: Vec3::new(shift, 0.0, 0.0),
        rotation: Mat3::identity(),
        axes: Vec3::new(2.0, 1.5, 1.0),
        value: shift,
    }];
    let camera = Camera::new(
        View::Iso,
        Projection::Perspective { fov_deg: 35.0 },
        Framing::enclosing(bodies.iter()),
        160,
        120,
    );
    render_frame(
        &bodies,
        &ColourScale::new("x (m)", -1.0, 1.0),
        &camera,
        &format!("t = {shift:.1} s"),
    )
    .unwrap()
}

#[test]
fn png_round_trips() {
    let image = test_frame(0.3);
    let path = scratch("frame.png");
    write_png(&path, &image).unwrap();
    let decoder = png::Decoder::new(std::fs::File::open(&path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (image.width, image.height));
    assert_eq!(info.color_type, png::ColorType::Rgb);
    assert_eq!(&buf[..info.buffer_size()], &image.pixels[..]);
}

#[test]
fn gif_holds_every_frame() {
    let path = scratch("run.gif");
    let mut gif = GifWriter::create(&path, 160, 120, 10).unwrap();
    for shift in [-1.0, 0.0, 1.0] {
        gif.add(&test_frame(shift)).unwrap();
    }
    // A frame of the wrong size is refused.
    assert!(gif.add(&RgbImage::new(10, 10, BG)).is_err());
    gif.finish().unwrap();

    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options.read_info(std::fs::File::open(&path).unwrap()).unwrap();
    assert_eq!((decoder.width(), decoder.height()), (160, 120));
    assert_eq!(decoder.repeat(), gif::Repeat::Infinite);
    let mut frames = 0;
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        assert_eq!((frame.width, frame.height), (160, 120));
        assert_eq!(frame.delay, 10);
        frames += 1;
    }
    assert_eq!(frames, 3);
}

#[test]
fn renders_inside_a_bounded_thread_pool() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let image = pool.install(|| test_frame(0.0));
    assert_eq!(image, test_frame(0.0));
}
