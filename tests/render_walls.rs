//! What `rubblepile render` adds to the bodies: translucent walls (their pixel colours against the documented
//! blend), the scale bar (its pixels against the camera's scale), the axis triad (its arrows against the view's
//! axes), the extent that follows the bodies (against hand-computed percentiles), and `--out` as a user calls it.

mod common;
use common::{rubblepile, temp_dir};
use std::path::{Path, PathBuf};

use rubblepile::engine::ParticleView;
use rubblepile::math::{Mat3, Vec3};
use rubblepile::render::overlay::{BAR_COLOUR, X_COLOUR, Y_COLOUR, Z_COLOUR};
use rubblepile::render::run::{following_framings, reach_98};
use rubblepile::render::{
    BACKGROUND, Camera, ColourScale, Framing, Projection, RenderBody, RgbImage, ScaleBar, Triad, View, WALL_ALPHA,
    WALL_COLOUR, WallPolygon, render_bodies, render_frame, render_scene,
};

const BG: [u8; 3] = [10, 20, 30];

/// Looking down −z at ±5 m across 200 px: 20 px per metre.
fn z_camera() -> Camera {
    let framing = Framing {
        centre: Vec3::zeros(),
        half_extent: 5.0,
    };
    Camera::new(View::Z, Projection::Orthographic, framing, 200, 200)
}

/// The shading factor of a face turned to ±z in the z view, from the documented light: l ∝ −right + up − 1.2·forward
/// = (−1, 1, 1.2), ambient 0.25 + diffuse 0.75·|n·l|.
fn z_face_shade() -> f64 {
    0.25 + 0.75 * 1.2 / (1.0_f64 + 1.0 + 1.44).sqrt()
}

fn square(z: f64, half: f64) -> Vec<Vec3> {
    vec![
        Vec3::new(-half, -half, z),
        Vec3::new(half, -half, z),
        Vec3::new(half, half, z),
        Vec3::new(-half, half, z),
    ]
}

/// One layer of wall over `under` (unrounded channel values), rounded as the renderer rounds.
fn over(under: [f64; 3], shade: f64) -> [u8; 3] {
    std::array::from_fn(|k| {
        (WALL_ALPHA * f64::from(WALL_COLOUR[k]) * shade + (1.0 - WALL_ALPHA) * under[k]).round() as u8
    })
}

#[test]
fn a_plane_wall_is_its_colour_blended_over_the_background_with_the_documented_alpha() {
    let camera = z_camera();
    // A 4 m square split into two triangles along its diagonal: the pixels on the shared edge are one layer too.
    let [a, b, c, d]: [Vec3; 4] = square(0.0, 2.0).try_into().unwrap();
    let walls = [
        WallPolygon::new(vec![a, b, c]).unwrap(),
        WallPolygon::new(vec![a, c, d]).unwrap(),
    ];
    let image = render_scene(&[], &walls, &camera, BG);
    let expected = over(BG.map(f64::from), z_face_shade());
    assert_ne!(expected, BG);
    // ±2 m = ±40 px about the centre (100, 100): pixels 60..140, edges left out.
    for y in 62..138 {
        for x in 62..138 {
            assert_eq!(image.get(x, y), expected, "pixel ({x}, {y})");
        }
    }
    for (x, y) in [(0, 0), (57, 100), (100, 143), (199, 199)] {
        assert_eq!(image.get(x, y), BG, "outside the wall: pixel ({x}, {y})");
    }
    // The same wall as one quad, and turned over (its vertices the other way round): the same picture.
    let quad = render_scene(&[], &[WallPolygon::new(square(0.0, 2.0)).unwrap()], &camera, BG);
    let mut flipped_points = square(0.0, 2.0);
    flipped_points.reverse();
    let flipped = render_scene(&[], &[WallPolygon::new(flipped_points).unwrap()], &camera, BG);
    assert_eq!(quad.get(100, 100), expected);
    assert_eq!(quad, flipped);
}

#[test]
fn a_sphere_behind_a_translucent_wall_is_visible_and_tinted_and_one_in_front_is_not() {
    let camera = z_camera();
    let colour = [200, 60, 60];
    // Centred under the middle of pixel (100, 100), so that pixel sees the ball's top, whose normal is +z.
    let ball = [RenderBody {
        centre: Vec3::new(0.025, -0.025, 0.0),
        rotation: Mat3::identity(),
        axes: Vec3::repeat(1.0),
        colour,
    }];
    let bare = render_bodies(&ball, &camera, BG);
    // The ball's top (normal +z) under the pixel at the centre is lit like the wall.
    let top = colour.map(|c| f64::from(c) * z_face_shade());
    assert_eq!(bare.get(100, 100), top.map(|c| c.round() as u8));

    // A wall between the camera (at +z) and the ball: the ball shows through, tinted by one layer.
    let in_front = [WallPolygon::new(square(2.0, 3.0)).unwrap()];
    let seen = render_scene(&ball, &in_front, &camera, BG);
    assert_eq!(seen.get(100, 100), over(top, z_face_shade()));
    assert_ne!(seen.get(100, 100), bare.get(100, 100));
    assert_eq!(
        seen.get(100, 100)[0].max(seen.get(100, 100)[1]),
        seen.get(100, 100)[0],
        "still red"
    );
    // Behind the ball: the ball is untouched, the background around it tinted.
    let behind = [WallPolygon::new(square(-2.0, 3.0)).unwrap()];
    let seen = render_scene(&ball, &behind, &camera, BG);
    assert_eq!(seen.get(100, 100), bare.get(100, 100));
    assert_eq!(seen.get(100, 50), over(BG.map(f64::from), z_face_shade()));
    // Both: background through two layers, the ball through one.
    let both = [in_front[0].clone(), behind[0].clone()];
    let seen = render_scene(&ball, &both, &camera, BG);
    assert_eq!(seen.get(100, 100), over(top, z_face_shade()));
    let once: [f64; 3] = std::array::from_fn(|k| {
        WALL_ALPHA * f64::from(WALL_COLOUR[k]) * z_face_shade() + (1.0 - WALL_ALPHA) * f64::from(BG[k])
    });
    assert_eq!(seen.get(100, 50), over(once, z_face_shade()));
}

/// Walls reaching from in front of a perspective eye to behind it (a floor under it, a side wall beside it): every
/// pixel is what its own ray gives, layer by layer — the culling of polygons to screen rectangles loses none.
#[test]
fn walls_reaching_behind_a_perspective_eye_are_drawn_wherever_their_rays_cross_them() {
    let framing = Framing {
        centre: Vec3::zeros(),
        half_extent: 1.0,
    };
    let camera = Camera::new(View::Iso, Projection::Perspective { fov_deg: 60.0 }, framing, 120, 90);
    // The eye is 2 m from the centre along (1, 1, 1): z = x = 1.155 m.
    let floor = square(0.5, 10.0);
    let side: Vec<Vec3> = floor.iter().map(|p| Vec3::new(1.0, p.x, p.y)).collect();
    let walls = [WallPolygon::new(floor).unwrap(), WallPolygon::new(side).unwrap()];
    let image = render_scene(&[], &walls, &camera, BG);
    let light = (-camera.right() + camera.up() - 1.2 * camera.forward()).normalize();
    let mut tinted = 0;
    for y in 0..camera.height() {
        for x in 0..camera.width() {
            let ray = camera.ray(x, y);
            let mut layers: Vec<(f64, f64)> = walls
                .iter()
                .filter_map(|w| {
                    w.hit(&ray, 0.0)
                        .map(|t| (t, 0.25 + 0.75 * w.normal().dot(&light).abs()))
                })
                .collect();
            layers.sort_by(|a, b| b.0.total_cmp(&a.0));
            let mut c = BG.map(f64::from);
            for (_, shade) in layers {
                c = std::array::from_fn(|k| WALL_ALPHA * f64::from(WALL_COLOUR[k]) * shade + (1.0 - WALL_ALPHA) * c[k]);
            }
            let expected = c.map(|v| v.round() as u8);
            tinted += usize::from(expected != BG);
            assert_eq!(image.get(x, y), expected, "pixel ({x}, {y})");
        }
    }
    assert!(tinted > 1000, "{tinted} pixels see a wall");
}

/// The longest horizontal run of `colour` in the image (pixels).
fn longest_run(image: &RgbImage, colour: [u8; 3]) -> u32 {
    let mut best = 0;
    for y in 0..image.height {
        let mut run = 0;
        for x in 0..image.width {
            run = if image.get(x, y) == colour { run + 1 } else { 0 };
            best = best.max(run);
        }
    }
    best
}

/// The number in a label such as "20 km" or "500 m", in metres.
fn label_metres(label: &str) -> f64 {
    let (v, unit) = label.split_once(' ').unwrap();
    let v: f64 = v.parse().unwrap();
    v * match unit {
        "km" => 1e3,
        "m" => 1.0,
        "mm" => 1e-3,
        _ => panic!("unit of {label:?}"),
    }
}

#[test]
fn the_scale_bar_spans_its_labelled_length_times_the_pixels_per_metre() {
    let scale = ColourScale::new("v (m/s)", 0.0, 1.0);
    // (half-extent m, width, height, projection, expected bar length m).
    let cases = [
        (5.0, 400, 300, Projection::Orthographic, 2.0),
        (5e4, 800, 800, Projection::Orthographic, 2e4),
        (0.3, 600, 400, Projection::Orthographic, 0.2),
        (120.0, 500, 500, Projection::Perspective { fov_deg: 40.0 }, 50.0),
    ];
    for (half, w, h, projection, metres) in cases {
        let framing = Framing {
            centre: Vec3::new(3.0, -1.0, 2.0),
            half_extent: half,
        };
        let camera = Camera::new(View::Iso, projection, framing, w, h);
        // The scale at the framing centre, from the camera's geometry: the shorter side spans ±half_extent there
        // (orthographic), or the field of view at the eye's distance half_extent / sin(fov/2) (perspective).
        let half_short = 0.5 * f64::from(w.min(h));
        let ppm = match projection {
            Projection::Orthographic => half_short / half,
            Projection::Perspective { fov_deg } => {
                let a = 0.5 * fov_deg.to_radians();
                half_short / (a.tan() * half / a.sin())
            }
        };
        assert!((camera.pixels_per_metre_at_centre() / ppm - 1.0).abs() < 1e-12);
        let bar = ScaleBar::for_camera(&camera).unwrap();
        assert_eq!(bar.metres, metres, "{half} m across {w} px");
        assert!((label_metres(&bar.label) / metres - 1.0).abs() < 1e-12, "{}", bar.label);
        assert_eq!(bar.pixels, (metres * ppm).round() as u32);
        // About a fifth of the width: within the 1-2-5 steps' factor √2.5 of it.
        let fifth = f64::from(w) / 5.0;
        assert!(f64::from(bar.pixels) / fifth < 1.6 && fifth / f64::from(bar.pixels) < 1.6);
        // On the frame: the longest horizontal run of the bar's colour is the bar.
        let image = render_frame(&[], &scale, &camera, "t = 1.0 s").unwrap();
        assert_eq!(longest_run(&image, BAR_COLOUR), bar.pixels, "{half} m across {w} px");
    }
    assert_eq!(rubblepile::render::overlay::length_label(200.0), "200 m");
    assert_eq!(rubblepile::render::overlay::length_label(0.5), "500 mm");
}

/// Pixels of exactly `colour`: their count and the extremes of their centres `(x_min, x_max, y_min, y_max)`.
fn pixels_of(image: &RgbImage, colour: [u8; 3]) -> (usize, (f64, f64, f64, f64)) {
    let mut n = 0;
    let mut b = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for y in 0..image.height {
        for x in 0..image.width {
            if image.get(x, y) == colour {
                let (cx, cy) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
                n += 1;
                b = (b.0.min(cx), b.1.max(cx), b.2.min(cy), b.3.max(cy));
            }
        }
    }
    (n, b)
}

#[test]
fn the_triad_x_arrow_points_right_in_the_z_view_and_at_the_viewer_in_the_x_view() {
    let origin = (50.0, 50.0);
    let length = 30.0;
    let thickness = 2.0;
    let draw = |view: View| {
        let camera = Camera::new(
            view,
            Projection::Orthographic,
            Framing {
                centre: Vec3::zeros(),
                half_extent: 1.0,
            },
            100,
            100,
        );
        let mut image = RgbImage::new(100, 100, BG);
        Triad::new(&camera, origin, length).draw(&mut image, thickness);
        image
    };
    // Looking down z: x to the right of the foot, y above it (the image's y grows downwards), z at the viewer (a
    // ring about the foot).
    let image = draw(View::Z);
    let (n, (x0, x1, y0, y1)) = pixels_of(&image, X_COLOUR);
    assert!(n > 20);
    assert!(
        x0 >= origin.0 - 1.0 && (x1 - (origin.0 + length)).abs() <= 2.0,
        "x: {x0}..{x1}"
    );
    assert!(
        y0 >= origin.1 - 1.5 * thickness - 1.0 && y1 <= origin.1 + 1.5 * thickness + 1.0,
        "x: {y0}..{y1}"
    );
    let (_, (x0, x1, y0, y1)) = pixels_of(&image, Y_COLOUR);
    assert!(
        y1 <= origin.1 + 1.0 && (y0 - (origin.1 - length)).abs() <= 2.0,
        "y: {y0}..{y1}"
    );
    assert!(x0 >= origin.0 - 1.5 * thickness - 1.0 && x1 <= origin.0 + 1.5 * thickness + 1.0);
    let (n, (x0, x1, y0, y1)) = pixels_of(&image, Z_COLOUR);
    assert!(n > 10);
    assert!((0.5 * (x0 + x1) - origin.0).abs() <= 1.0 && (0.5 * (y0 + y1) - origin.1).abs() <= 1.0);
    // Looking down x (from +x): y to the right, z up, x at the viewer.
    let image = draw(View::X);
    let (_, (x0, x1, _, _)) = pixels_of(&image, Y_COLOUR);
    assert!(x0 >= origin.0 - 1.0 && (x1 - (origin.0 + length)).abs() <= 2.0);
    let (_, (_, _, y0, _)) = pixels_of(&image, Z_COLOUR);
    assert!((y0 - (origin.1 - length)).abs() <= 2.0);
    let (_, (x0, x1, y0, y1)) = pixels_of(&image, X_COLOUR);
    assert!((0.5 * (x0 + x1) - origin.0).abs() <= 1.0 && (0.5 * (y0 + y1) - origin.1).abs() <= 1.0);
    // Every frame carries a triad in its bottom-left corner.
    let frame = render_frame(&[], &ColourScale::new("v", 0.0, 1.0), &z_camera(), "").unwrap();
    let (n, (x0, _, y0, _)) = pixels_of(&frame, X_COLOUR);
    assert!(n > 10 && x0 < 100.0 && y0 > 100.0, "{n} pixels from ({x0}, {y0})");
}

fn ball(id: usize, position: Vec3) -> ParticleView {
    ParticleView::sphere(id, 1.0, 1.0, position, Vec3::zeros(), Vec3::zeros())
}

/// 100 unit balls on a ring of `radius` about `centre` in the xy plane, and two far-off escapers.
fn ring(radius: f64, centre: Vec3) -> Vec<ParticleView> {
    let mut out: Vec<ParticleView> = (0..100)
        .map(|k| {
            let phi = std::f64::consts::TAU * k as f64 / 100.0;
            ball(k, centre + radius * Vec3::new(phi.cos(), phi.sin(), 0.0))
        })
        .collect();
    // Escapers in opposite directions: the centre of mass stays at `centre`.
    out.push(ball(100, centre + Vec3::new(0.0, 0.0, 1e4)));
    out.push(ball(101, centre - Vec3::new(0.0, 0.0, 1e4)));
    out
}

#[test]
fn the_extent_follows_an_expanding_pile_and_never_shrinks() {
    // 98 % of 102 bodies is 100 (nearest rank): the ring holds them, the two escapers do not widen the picture.
    let (centre, reach) = reach_98(&ring(10.0, Vec3::new(5.0, 0.0, 0.0)));
    assert!((centre - Vec3::new(5.0, 0.0, 0.0)).norm() < 1e-9);
    assert!((reach - 11.0).abs() < 1e-9, "{reach}");
    // A few bodies (an impact's first snapshot, projectile far out): up to 49 bodies, all are held.
    let few: Vec<ParticleView> = ring(10.0, Vec3::zeros()).into_iter().skip(60).collect();
    assert!((reach_98(&few).1 - 1e4 - 1.0).abs() < 0.01);

    // Expanding, drifting, then contracting: the half-width grows with the reach (plus the 5 % margin) and then
    // holds; the centre follows the centre of mass.
    let radii = [10.0, 20.0, 40.0, 80.0, 30.0, 10.0];
    let reaches: Vec<(Vec3, f64)> = radii
        .iter()
        .enumerate()
        .map(|(k, &r)| reach_98(&ring(r, Vec3::new(0.0, 3.0 * k as f64, 0.0))))
        .collect();
    let framings = following_framings(&reaches, None);
    let expected = [11.0, 21.0, 41.0, 81.0, 81.0, 81.0].map(|r| r * (1.0 + Framing::MARGIN));
    for (k, f) in framings.iter().enumerate() {
        assert!(
            (f.half_extent - expected[k]).abs() < 1e-9,
            "frame {k}: {}",
            f.half_extent
        );
        assert!((f.centre - Vec3::new(0.0, 3.0 * k as f64, 0.0)).norm() < 1e-9);
    }
    assert!(framings.windows(2).all(|w| w[1].half_extent >= w[0].half_extent));
    // A fixed extent stays fixed.
    assert!(
        following_framings(&reaches, Some(7.0))
            .iter()
            .all(|f| f.half_extent == 7.0)
    );
    // Nothing to frame: 1 m about the origin.
    assert_eq!(following_framings(&[reach_98(&[])], None)[0].half_extent, 1.0);
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn ok(o: &std::process::Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn read_png(path: &Path) -> RgbImage {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    assert_eq!(info.color_type, png::ColorType::Rgb);
    RgbImage {
        width: info.width,
        height: info.height,
        pixels: buf,
    }
}

#[test]
fn out_puts_a_second_view_elsewhere_and_an_existing_one_is_kept_without_force() {
    let dir = temp_dir("render-out");
    let scene = root().join("targets/examples/soft_spheres.toml");
    ok(&rubblepile(
        &dir,
        &["run", scene.to_str().unwrap(), "--out", "soft", "--no-progress"],
    ));
    let text = ok(&rubblepile(
        &dir,
        &[
            "render",
            "soft",
            "--view",
            "y",
            "--size",
            "160x120",
            "--out",
            "views/side",
        ],
    ));
    assert!(text.contains("views/side"), "{text}");
    assert!(dir.join("views/side/run.gif").exists());
    assert!(dir.join("views/side/0000.png").exists());
    assert!(
        !dir.join("soft/frames").exists(),
        "nothing written to the default place"
    );
    // The ball sits inside a spherical container of radius 5 m, far wider than the frame: every ray crosses its two
    // layers, so even the frame's corners are lighter than the bare background.
    let frame = read_png(&dir.join("views/side/0000.png"));
    let corner = frame.get(frame.width - 2, frame.height - 2);
    assert!(
        (0..3).all(|k| corner[k] > BACKGROUND[k]),
        "{corner:?} against {BACKGROUND:?}"
    );
    // A second render into the same directory is refused (exit 2, naming --force) and leaves it as it was.
    let before = std::fs::read(dir.join("views/side/0000.png")).unwrap();
    let o = rubblepile(
        &dir,
        &[
            "render",
            "soft",
            "--view",
            "z",
            "--size",
            "160x120",
            "--out",
            "views/side",
        ],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--force"));
    assert_eq!(std::fs::read(dir.join("views/side/0000.png")).unwrap(), before);
    // With --force it is overwritten; the default place still works beside it.
    ok(&rubblepile(
        &dir,
        &[
            "render",
            "soft",
            "--view",
            "z",
            "--size",
            "160x120",
            "--out",
            "views/side",
            "--force",
        ],
    ));
    assert_ne!(std::fs::read(dir.join("views/side/0000.png")).unwrap(), before);
    ok(&rubblepile(&dir, &["render", "soft", "--size", "160x120"]));
    assert!(dir.join("soft/frames/run.gif").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A spherical container (radius 1 m) swinging ±0.5 m along x at 1 Hz around a ball at rest, drawn at t = 0.25 s
/// and 0.75 s (offsets +0.5 m and −0.5 m) looking down z, 400 px across ±3 m: the container's left edge on the
/// middle row lies at 200 px + (offset − 1 m) × 66.7 px/m in each frame.
#[test]
fn a_moving_wall_is_drawn_where_it_was_at_each_snapshot() {
    let dir = temp_dir("render-moving-wall");
    std::fs::write(
        dir.join("scene.toml"),
        r#"[scene]
kind = "soft-spheres"
t_end = 1.0

[stepping]
dt = 1e-3

[material]
k_n = 1e3

[output]
every = 0.25
times = [0.25, 0.75]

[[wall]]
kind = "sphere"
centre = [0.0, 0.0, 0.0]
radius = 1.0
oscillation = { amplitude = 0.5, direction = [1.0, 0.0, 0.0], angular_frequency = 6.283185307179586 }

[[particle]]
radius = 0.1
density = 2000.0
position = [0.0, 0.0, 0.0]
"#,
    )
    .unwrap();
    ok(&rubblepile(
        &dir,
        &["run", "scene.toml", "--out", "run", "--no-progress"],
    ));
    ok(&rubblepile(
        &dir,
        &[
            "render",
            "run",
            "--view",
            "z",
            "--size",
            "400x400",
            "--extent-m",
            "3",
            "--out",
            "views",
        ],
    ));
    let ppm = 200.0 / 3.0;
    for (k, offset) in [(0, 0.5), (1, -0.5)] {
        let frame = read_png(&dir.join(format!("views/{k:04}.png")));
        let left = (0..frame.width)
            .find(|&x| frame.get(x, frame.height / 2) != BACKGROUND)
            .unwrap();
        let expected = 200.0 + (offset - 1.0) * ppm;
        assert!(
            (f64::from(left) + 0.5 - expected).abs() <= 1.0,
            "frame {k}: edge at pixel {left}, expected {expected:.1}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
