//! The hard-sphere summary's bookkeeping (issue 41): the energy lost to restitution and the moving walls' work, and
//! the momentum the walls and the gravity field gave, are reported apart from the residuals, so that `energy_error`
//! and `momentum_error` are errors (rounding) while the raw changes are large. A box of inelastic spheres shaken by
//! an oscillating floor.

mod common;

use common::{rubblepile, temp_dir};

/// Twelve spheres (ε_n 0.6, ε_t 0.5) in a cylinder between a floor oscillating at 0.6 m/s and a fixed ceiling.
fn scene(gravity: bool) -> String {
    scene_dt(gravity, 1e-3)
}

/// [`scene`] with the step `dt` (s).
fn scene_dt(gravity: bool, dt: f64) -> String {
    let mut s = format!(
        "[scene]\nkind = \"hard-spheres\"\nt_end = 1.0\nseed = 3\n[stepping]\ndt = {dt:?}\ncollapse_speed = 1e-6\n",
    );
    if gravity {
        s += "[gravity]\nuniform = [0.0, 0.0, -9.81]\n";
    }
    s += "[material]\neps_n = 0.6\neps_t = 0.5\n[output]\ntimes = [0.0, 1.0]\nevery = 0.1\n";
    for k in 0..12 {
        let (x, y, z) = (
            -0.15 + 0.1 * (k % 4) as f64,
            -0.05 + 0.1 * ((k / 4) % 2) as f64,
            0.1 + 0.12 * (k / 4) as f64,
        );
        let v = [
            0.5 - 0.07 * k as f64,
            0.3 - 0.05 * (k % 5) as f64,
            -0.4 + 0.06 * k as f64,
        ];
        s += &format!(
            "[[particle]]\nmass = {:?}\nradius = 0.04\nposition = [{x:?}, {y:?}, {z:?}]\nvelocity = [{:?}, {:?}, {:?}]\n",
            1.0 + 0.1 * k as f64,
            v[0],
            v[1],
            v[2]
        );
    }
    s += "[[wall]]\nkind = \"cylinder\"\nradius = 0.3\nlength = 2.0\n";
    s += "[[wall]]\nkind = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n\
          oscillation = { amplitude = 0.01, angular_frequency = 60.0 }\n";
    s += "[[wall]]\nkind = \"plane\"\npoint = [0.0, 0.0, 0.5]\nnormal = [0.0, 0.0, -1.0]\n";
    s
}

fn run(gravity: bool, tag: &str) -> serde_json::Value {
    run_scene(&scene(gravity), tag)
}

fn run_scene(text: &str, tag: &str) -> serde_json::Value {
    let dir = temp_dir(tag);
    std::fs::write(dir.join("s.toml"), text).unwrap();
    let out = rubblepile(&dir, &["run", "s.toml", "--out", "a", "--no-progress"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_str(&std::fs::read_to_string(dir.join("a/summary.json")).unwrap()).unwrap()
}

fn num(s: &serde_json::Value, key: &str) -> f64 {
    s[key].as_f64().unwrap_or_else(|| panic!("summary lacks {key}: {s}"))
}

#[test]
fn restitution_and_moving_walls_are_apart_from_the_energy_residual() {
    let s = run(false, "hsdem-book-energy");
    assert_eq!(s["status"], "completed");
    assert!(s["wall_collisions"].as_u64().unwrap() > 10, "{s}");
    // The energy changed a lot (inelastic collisions, the shaking floor) ...
    assert!(num(&s, "energy_change") > 0.1, "{s}");
    assert!(num(&s, "energy_restitution") < 0.0, "{s}");
    assert!(num(&s, "energy_walls").abs() > 1e-3, "{s}");
    // ... the parts add up to the exchanged energy ...
    let parts = num(&s, "energy_restitution") + num(&s, "energy_walls") + num(&s, "energy_removed");
    let exchanged = num(&s, "energy_exchanged");
    assert!(
        (parts - exchanged).abs() < 1e-12 * exchanged.abs().max(1.0),
        "{parts} vs {exchanged}"
    );
    // ... and the error is rounding.
    assert!(num(&s, "energy_error") < 1e-12, "{s}");
    // Momentum: the walls' impulse accounts for the whole change.
    assert!(num(&s, "momentum_change") > 0.1, "{s}");
    assert!(num(&s, "momentum_error") < 1e-12 * num(&s, "momentum_change"), "{s}");
}

#[test]
fn the_gravity_fields_impulse_is_apart_from_the_momentum_residual() {
    let s = run(true, "hsdem-book-gravity");
    assert_eq!(s["status"], "completed");
    // Twelve free spheres of 1.0 .. 2.1 kg (total 18.6 kg) under 9.81 m/s² for 1 s.
    let expected = 18.6 * 9.81;
    let field = num(&s, "field_impulse");
    assert!(
        (field - expected).abs() < 1e-12 * expected,
        "field impulse {field} vs {expected}"
    );
    assert!(num(&s, "momentum_change") > 1.0, "{s}");
    assert!(num(&s, "momentum_error") < 1e-12 * expected, "{s}");
}

/// Five elastic spheres (ε_n = ε_t = 1) bouncing on a fixed floor under gravity, far enough apart never to meet,
/// stepped with `dt` (s): the exact motion conserves energy, so every bit of residual is integration error.
fn bouncing_balls(dt: f64) -> String {
    let mut s = format!(
        "[scene]\nkind = \"hard-spheres\"\nt_end = 2.0\nseed = 3\n[stepping]\ndt = {dt:?}\ncollapse_speed = 0.0\n\
         [gravity]\nuniform = [0.0, 0.0, -9.81]\n[material]\neps_n = 1.0\neps_t = 1.0\n[output]\ntimes = [0.0, 2.0]\nevery = 0.05\n"
    );
    for k in 0..5 {
        let (x, z, vz) = (0.1 * k as f64, 0.05 + 0.037 * k as f64, 0.1 * k as f64);
        s += &format!(
            "[[particle]]\nmass = 1.0\nradius = 0.01\nposition = [{x:?}, 0.0, {z:?}]\nvelocity = [0.0, 0.0, {vz:?}]\n"
        );
    }
    s + "[[wall]]\nkind = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n"
}

/// Guards the explanation of the tumbler's energy residual (Richardson11 NOTES): under gravity the residual is the
/// kick–drift–kick splitting error of collisions inside a step — a sphere drifts on a straight line with its
/// mid-step velocity, so at a bounce its speed is off by up to g dt / 2 and each bounce gains or loses up to
/// m u g dt — not a bookkeeping leak. With the bounces fixed in number it must fall in proportion to dt; a leak
/// (an unbooked impulse) would not move with dt.
#[test]
fn the_energy_residual_under_gravity_is_the_splitting_error_and_falls_with_the_step() {
    let run = |dt: f64, tag: &str| {
        let s = run_scene(&bouncing_balls(dt), tag);
        assert_eq!(s["status"], "completed");
        (num(&s, "energy_error"), num(&s, "collisions"))
    };
    let (coarse, n_coarse) = run(2e-3, "hsdem-book-dt2");
    let (middle, n_middle) = run(1e-3, "hsdem-book-dt1");
    let (fine, n_fine) = run(5e-4, "hsdem-book-dt05");
    for n in [n_coarse, n_middle, n_fine] {
        assert!((30.0..=40.0).contains(&n), "the same ≈ 35 bounces at every step: {n}");
    }
    assert!(fine > 1e-6, "a splitting error to measure: {fine:e}");
    for (a, b) in [(coarse, middle), (middle, fine)] {
        assert!(a / b > 1.6, "halving dt must about halve the residual: {a:e} → {b:e}");
    }
}
