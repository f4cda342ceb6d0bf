//! The four spring-frame tests of our notes (`shared/notes/ssdem.md`, "Springs follow the contact frame"):
//! rigid co-rotation keeps the springs fixed in the pair's frame with unchanged length; steady relative rolling
//! grows the rolling torque linearly up to μ_R β R |F_N|; an elastic load–unload cycle returns the springs to
//! zero; pure twist leaves the rolling spring untouched.

use nalgebra::Rotation3;
use rubblepile::granular::soft::contact::{Kinematics, Material, Springs, evaluate};
use rubblepile::math::Vec3;

const R: f64 = 1.0;
const MASS: f64 = 1000.0;

/// Kinematics of two equal spheres (radius R) at `xi`, `xj` with velocities and spins.
fn kin(xi: Vec3, xj: Vec3, vi: Vec3, vj: Vec3, wi: Vec3, wj: Vec3) -> Kinematics {
    let d = xj - xi;
    let dist = d.norm();
    let n = d / dist;
    let overlap = 2.0 * R - dist;
    let l = R - 0.5 * overlap;
    Kinematics {
        normal: n,
        overlap,
        lever_i: l,
        lever_j: l,
        relative_velocity: vj - vi - wj.cross(&n) * l - wi.cross(&n) * l,
        spin_i: wi,
        spin_j: wj,
        r_eff: 0.5 * R,
        mass_eff: 0.5 * MASS,
    }
}

fn material() -> Material {
    Material::nominal(1e6)
}

#[test]
fn rigidly_corotating_pair_keeps_its_springs_in_the_body_frame() {
    let omega = Vec3::new(0.3, -0.2, 1.0); // rad/s, not along the normal nor perpendicular to it
    let half = Vec3::new(R - 0.005, 0.0, 0.0);
    let shear0 = Vec3::new(0.0, 1e-3, 5e-4);
    let roll0 = Vec3::new(0.0, -0.004, 0.01);
    let mut springs = Springs {
        normal: Vec3::x(),
        shear: shear0,
        twist: 0.0,
        roll: roll0,
    };
    let steps = 2000;
    let t_total = 0.25 * std::f64::consts::TAU / omega.norm();
    let dt = t_total / steps as f64;
    for k in 1..=steps {
        let rot = Rotation3::from_scaled_axis(omega * (k as f64 * dt));
        let (xi, xj) = (rot * -half, rot * half);
        let out = evaluate(
            &material(),
            &kin(xi, xj, omega.cross(&xi), omega.cross(&xj), omega, omega),
            &mut springs,
            dt,
        );
        assert!(out.normal_force > 0.0);
    }
    let rot = Rotation3::from_scaled_axis(omega * t_total);
    let (e_shear, e_roll) = (
        (springs.shear - rot * shear0).norm() / shear0.norm(),
        (springs.roll - rot * roll0).norm() / roll0.norm(),
    );
    let len = (springs.shear.norm() / shear0.norm() - 1.0)
        .abs()
        .max((springs.roll.norm() / roll0.norm() - 1.0).abs());
    println!(
        "quarter turn in {steps} steps: shear off by {e_shear:.2e}, roll by {e_roll:.2e}, length change {len:.2e}"
    );
    assert!(
        e_shear < 1e-5 && e_roll < 1e-5,
        "springs left the body frame: {e_shear}, {e_roll}"
    );
    assert!(len < 1e-12, "spring lengths changed by {len}");
}

#[test]
fn steady_relative_rolling_grows_the_torque_linearly_to_its_cap() {
    let m = material();
    let w = 0.05; // rad/s, j rolls about y relative to i
    let (xi, xj) = (Vec3::new(-(R - 0.005), 0.0, 0.0), Vec3::new(R - 0.005, 0.0, 0.0));
    let k_state = kin(
        xi,
        xj,
        Vec3::zeros(),
        Vec3::zeros(),
        Vec3::zeros(),
        Vec3::new(0.0, w, 0.0),
    );
    let mut springs = Springs::new(Vec3::x());
    let dt = 1e-3;
    let k_r = m.k_n * (m.beta * 0.5 * R).powi(2);
    let c_r = rubblepile::granular::soft::contact::damping(m.eps_n, m.k_n, 0.5 * MASS) * (m.beta * 0.5 * R).powi(2);
    let mut capped_at = None;
    for step in 1..=20_000 {
        let out = evaluate(&m, &k_state, &mut springs, dt);
        let cap = m.mu_r * m.beta * 0.5 * R * out.normal_force;
        let linear = k_r * w * dt * step as f64 + c_r * w;
        if linear < cap * (1.0 - 1e-9) {
            assert!(
                (out.rolling_torque - linear).abs() <= 1e-9 * linear,
                "step {step}: torque {} is not linear ({linear})",
                out.rolling_torque
            );
        } else {
            assert!(
                out.rolling_torque <= cap * (1.0 + 1e-12),
                "step {step}: torque above the cap"
            );
            capped_at.get_or_insert(step);
        }
        if let Some(s) = capped_at
            && step > s + 10
        {
            assert!((out.rolling_torque - cap).abs() <= 1e-12 * cap, "the cap is not held");
            println!("rolling torque linear for {s} steps, then held at mu_R beta R |F_N| = {cap:.6e} N m");
            return;
        }
    }
    panic!("the rolling torque never reached its cap");
}

#[test]
fn elastic_load_unload_cycle_returns_the_springs_to_zero() {
    let m = Material {
        eps_n: 1.0,
        eps_t: 1.0,
        ..material()
    };
    let (xi, xj) = (Vec3::new(-(R - 0.005), 0.0, 0.0), Vec3::new(R - 0.005, 0.0, 0.0));
    let v = Vec3::new(0.0, 2e-3, -1e-3);
    let w = Vec3::new(0.0, 0.01, 0.02);
    let mut springs = Springs::new(Vec3::x());
    let dt = 1e-3;
    let mut peak: f64 = 0.0;
    for sign in [1.0, -1.0] {
        for _ in 0..500 {
            evaluate(
                &m,
                &kin(xi, xj, Vec3::zeros(), v * sign, Vec3::zeros(), w * sign),
                &mut springs,
                dt,
            );
            peak = peak.max(springs.shear.norm());
        }
    }
    println!(
        "after load and unload: |shear| = {:.2e} (peak {peak:.2e}), twist = {:.2e}, |roll| = {:.2e}",
        springs.shear.norm(),
        springs.twist,
        springs.roll.norm()
    );
    assert!(peak > 1e-4, "the load did not stretch the spring");
    assert!(springs.shear.norm() < 1e-15 && springs.twist.abs() < 1e-15 && springs.roll.norm() < 1e-15);
}

#[test]
fn pure_twist_leaves_the_rolling_spring_untouched() {
    let m = material();
    let (xi, xj) = (Vec3::new(-(R - 0.005), 0.0, 0.0), Vec3::new(R - 0.005, 0.0, 0.0));
    let roll0 = Vec3::new(0.0, 3e-3, -1e-3);
    let mut springs = Springs {
        normal: Vec3::x(),
        shear: Vec3::zeros(),
        twist: 0.0,
        roll: roll0,
    };
    let twist = Vec3::new(0.2, 0.0, 0.0); // j spins about the normal relative to i
    let dt = 1e-3;
    for _ in 0..200 {
        evaluate(
            &m,
            &kin(xi, xj, Vec3::zeros(), Vec3::zeros(), -twist * 0.5, twist * 0.5),
            &mut springs,
            dt,
        );
    }
    println!(
        "after 200 twist steps: twist = {:.4e} rad, roll change = {:.2e}",
        springs.twist,
        (springs.roll - roll0).norm()
    );
    assert!(springs.twist.abs() > 0.0, "no twist accumulated");
    assert!(
        (springs.roll - roll0).norm() < 1e-15,
        "the rolling spring moved: {:?}",
        springs.roll
    );
    assert!(springs.shear.norm() < 1e-15, "the shear spring moved");
}

/// The trigonometry-free frame rotation (spring_frame.rs) equals the composition of the shortest-arc rotation
/// from the old to the new normal and the rotation about the new normal by the mean spin about the mean normal,
/// built with axis–angle rotations, for small and large steps and nearly antiparallel normals.
#[test]
fn frame_rotation_equals_the_axis_angle_composition() {
    use nalgebra::Unit;
    use rubblepile::granular::soft::spring_frame::FrameRotation;
    let mut rng = rubblepile::random::generator(3);
    let mut unit = || rubblepile::random::point_in_ball(&mut rng, 1.0).normalize();
    let mut worst: f64 = 0.0;
    for case in 0..400 {
        let n_old = unit();
        // tilts from 1e-6 rad to nearly half a turn, twist angles from 1e-7 rad to 2 rad
        let tilt = [1e-6, 1e-3, 0.1, 1.0, 2.5, std::f64::consts::PI - 1e-4][case % 6];
        let perp = (unit().cross(&n_old)).normalize();
        let n_new = Rotation3::from_axis_angle(&Unit::new_normalize(perp), tilt) * n_old;
        let spin = unit() * [1e-4, 1.0, 30.0, 1e3][case % 4];
        let dt = 2e-3;
        let mean_normal = (n_old + n_new).normalize();
        let axis = n_old.cross(&n_new);
        let swing = Rotation3::from_axis_angle(&Unit::new_normalize(axis), axis.norm().atan2(n_old.dot(&n_new)));
        let expected = Rotation3::from_axis_angle(&Unit::new_normalize(n_new), spin.dot(&mean_normal) * dt) * swing;
        let r = FrameRotation::new(&n_old, &n_new, &spin, dt);
        for v in [unit(), unit() * 1e-3] {
            let err = (r.apply(&v) - expected * v).norm() / v.norm();
            worst = worst.max(err);
            assert!(
                (r.apply(&v).norm() - v.norm()).abs() <= 1e-14 * v.norm(),
                "length not kept"
            );
        }
    }
    assert!(worst < 1e-13, "largest relative difference {worst:e}");
}
