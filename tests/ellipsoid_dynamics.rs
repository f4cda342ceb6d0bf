//! Dynamics of the interacting-ellipsoids model against analytic references and conservation laws.

mod common;
use common::{Random, integrate, rock};
use rubblepile::ellipsoid::body::InertiaModel;
use rubblepile::ellipsoid::calibration::calibrate_kappa;
use rubblepile::ellipsoid::equations::{
    ContactTerm, DissipationTerm, EllipsoidSystem, G_SI, GravityTerm, ModelConfig, Physics,
};
use rubblepile::integrate::{Method, OdeSystem, Tolerances, make_integrator};
use rubblepile::math::{Vec3, Vec4};

/// Euler's equations `I ω̇ = (I ω) × ω` of a free rigid body, in the body frame (an independent reference).
struct EulerEquations {
    moments: Vec3,
}

impl OdeSystem for EulerEquations {
    fn dim(&self) -> usize {
        3
    }
    fn rhs(&self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        let w = Vec3::new(y[0], y[1], y[2]);
        let l = self.moments.component_mul(&w);
        let rate = l.cross(&w).component_div(&self.moments);
        dydt.copy_from_slice(rate.as_slice());
    }
}

#[test]
fn torque_free_asymmetric_top_matches_euler_equations() {
    let mut rng = Random::new(11);
    let spin = [0.02, 0.05, 0.5];
    let body = rock([3.0, 2.0, 1.0], [0.0; 3], [0.0; 3], rng.unit_quaternion(), spin);
    let model = ModelConfig {
        kappa: 10.0,
        inertia: InertiaModel::Gaussian,
        contact_g: G_SI,
    };
    let sys = EllipsoidSystem::new(&[body], model, Physics::default());
    assert!(sys.rotation_integrated());
    let period = 2.0 * std::f64::consts::PI / Vec3::from(spin).norm();
    let t_end = 60.0 * period;
    let reference = EulerEquations {
        moments: sys.principal_moments()[0],
    };
    let mut integ = make_integrator(
        Method::BulirschStoer,
        Tolerances::uniform(1e-11, 1e-11, sys.dim()),
        None,
    )
    .unwrap();
    let mut reference_integ = make_integrator(Method::Dop853, Tolerances::uniform(1e-13, 1e-13, 3), None).unwrap();
    let (mut t, mut t_ref) = (0.0, 0.0);
    let mut y = sys.initial_state();
    let mut w_ref = spin.to_vec();
    let mut worst: f64 = 0.0;
    let mut worst_q: f64 = 0.0;
    for k in 1..=120 {
        let target = t_end * k as f64 / 120.0;
        integ.advance(&sys, &mut t, &mut y, target).unwrap();
        reference_integ
            .advance(&reference, &mut t_ref, &mut w_ref, target)
            .unwrap();
        let w = sys.bodies_at(t, &y)[0].spin_body;
        let err = (w - Vec3::from_column_slice(&w_ref)).norm() / Vec3::from(spin).norm();
        worst = worst.max(err);
        worst_q = worst_q.max(sys.diagnostics(&y).quaternion_norm_error);
    }
    eprintln!(
        "top: {:.0} periods, max relative spin error {worst:e}, max ||q|-1| {worst_q:e}, stats {:?}",
        t_end / period,
        integ.stats()
    );
    assert!(worst <= 1e-8, "body spin differs from Euler's equations by {worst:e}");
    assert!(worst_q <= 1e-9, "||q| - 1| = {worst_q:e}");
}

/// Two spinning km-size ellipsoids on a grazing approach (impact parameter ~ 0.6 of the sum of major axes),
/// faster than the mutual escape speed, so they collide, rebound and separate.
fn grazing_pair(physics: Physics) -> EllipsoidSystem {
    let mut rng = Random::new(12);
    let a = rock(
        [1000.0, 700.0, 500.0],
        [-2500.0, -600.0, 0.0],
        [1.2, 0.0, 0.0],
        rng.unit_quaternion(),
        [2e-4, -1e-4, 8e-4],
    );
    let b = rock(
        [900.0, 800.0, 600.0],
        [2500.0, 600.0, 50.0],
        [-1.2, 0.0, 0.0],
        rng.unit_quaternion(),
        [-3e-4, 5e-4, 1e-4],
    );
    let (ra, rb) = (a.shape.equivalent_radius(), b.shape.equivalent_radius());
    let (small, large) = if a.shape.mass < b.shape.mass {
        (&a, &b)
    } else {
        (&b, &a)
    };
    let kappa = calibrate_kappa(
        10.0,
        2.4,
        small.shape.equivalent_radius(),
        small.shape.mass,
        large.shape.equivalent_radius(),
        G_SI,
    )
    .unwrap();
    let _ = (ra, rb);
    let model = ModelConfig {
        kappa,
        inertia: InertiaModel::Gaussian,
        contact_g: G_SI,
    };
    EllipsoidSystem::new(&[a, b], model, physics)
}

const T_COLLISION: f64 = 4000.0;

fn conservative() -> Physics {
    Physics {
        gravity: Some(GravityTerm::new(G_SI)),
        contact: Some(ContactTerm::default()),
        dissipation: None,
    }
}

#[test]
fn grazing_collision_conserves_energy_and_momenta() {
    let sys = grazing_pair(conservative());
    let rtol = 1e-10;
    let (y, e, stats) = integrate(&sys, Method::BulirschStoer, rtol, T_COLLISION, 80);
    eprintln!("grazing elastic: {e:?} {stats:?}");
    // it did collide: the spins changed
    let b = sys.bodies_at(T_COLLISION, &y);
    let b0 = sys.bodies_at(0.0, &sys.initial_state());
    assert!(
        (b[0].spin_body - b0[0].spin_body).norm() > 1e-2 * b0[0].spin_body.norm(),
        "no spin exchange: no contact?"
    );
    // and rebounded: moving apart at the end
    assert!((b[1].position - b[0].position).dot(&(b[1].velocity - b[0].velocity)) > 0.0);
    assert!(e.energy <= 10.0 * rtol, "energy error {:e}", e.energy);
    assert!(e.momentum <= 10.0 * rtol, "momentum error {:e}", e.momentum);
    assert!(
        e.angular_momentum <= 10.0 * rtol,
        "angular momentum error {:e}",
        e.angular_momentum
    );
}

#[test]
fn dissipative_collision_balances_energy_and_conserves_momenta() {
    let physics = Physics {
        dissipation: Some(DissipationTerm { f0: 1.0 }),
        ..conservative()
    };
    let sys = grazing_pair(physics);
    let rtol = 1e-10;
    let (_, e, stats) = integrate(&sys, Method::BulirschStoer, rtol, T_COLLISION, 80);
    eprintln!("grazing dissipative: {e:?} {stats:?}");
    assert!(e.energy <= 10.0 * rtol, "energy residual H - H0 - 2∫F: {:e}", e.energy);
    assert!(e.momentum <= 10.0 * rtol, "momentum error {:e}", e.momentum);
    assert!(
        e.angular_momentum <= 10.0 * rtol,
        "angular momentum error {:e}",
        e.angular_momentum
    );
    assert!(
        e.dissipated_fraction > 0.01,
        "only {:e} of the kinetic energy dissipated",
        e.dissipated_fraction
    );
}

#[test]
fn common_rigid_motion_dissipates_nothing() {
    // two overlapping ellipsoids turning together as one rigid body
    let mut rng = Random::new(13);
    let omega = Vec3::new(1e-4, -2e-4, 5e-4);
    let (ra, rb) = (Vec3::new(-700.0, 100.0, 0.0), Vec3::new(800.0, -50.0, 40.0));
    let (qa, qb) = (rng.unit_quaternion(), rng.unit_quaternion());
    let spin_body = |q: &Vec4| rubblepile::ellipsoid::quaternion::rotation_matrix(q) * omega;
    let a = rock(
        [1000.0, 700.0, 500.0],
        ra.into(),
        omega.cross(&ra).into(),
        qa,
        spin_body(&qa).into(),
    );
    let b = rock(
        [900.0, 800.0, 600.0],
        rb.into(),
        omega.cross(&rb).into(),
        qb,
        spin_body(&qb).into(),
    );
    let model = ModelConfig {
        kappa: 5.0,
        inertia: InertiaModel::Gaussian,
        contact_g: G_SI,
    };
    let physics = Physics {
        dissipation: Some(DissipationTerm { f0: 1.0 }),
        ..conservative()
    };
    let sys = EllipsoidSystem::new(&[a.clone(), b.clone()], model, physics);
    let y = sys.initial_state();
    let mut dy = vec![0.0; sys.dim()];
    sys.rhs(0.0, &y, &mut dy);
    let f_rigid = dy[sys.dissipation_index().unwrap()];
    // the same bodies with b's motion reversed dissipate at a rate that sets the scale
    let mut b2 = b;
    b2.velocity = -b2.velocity;
    b2.spin_body = -b2.spin_body;
    let sys2 = EllipsoidSystem::new(&[a, b2], model, physics);
    sys2.rhs(0.0, &sys2.initial_state(), &mut dy);
    let f_scale = dy[sys2.dissipation_index().unwrap()];
    assert!(f_scale < 0.0);
    assert!(
        f_rigid.abs() <= 1e-12 * f_scale.abs(),
        "rigid motion dissipates {f_rigid:e} (scale {f_scale:e})"
    );
}

#[test]
fn bulirsch_stoer_and_dop853_agree_on_collision() {
    let sys = grazing_pair(conservative());
    let (y_bs, _, s_bs) = integrate(&sys, Method::BulirschStoer, 1e-12, T_COLLISION, 4);
    let (y_dp, _, s_dp) = integrate(&sys, Method::Dop853, 1e-12, T_COLLISION, 4);
    eprintln!("BS {s_bs:?}\nDop853 {s_dp:?}");
    let (bs, dp) = (sys.bodies_at(T_COLLISION, &y_bs), sys.bodies_at(T_COLLISION, &y_dp));
    let scale_r: f64 = bs.iter().map(|b| b.position.norm()).fold(0.0, f64::max);
    let scale_v: f64 = bs.iter().map(|b| b.velocity.norm()).fold(0.0, f64::max);
    let scale_w: f64 = bs.iter().map(|b| b.spin_body.norm()).fold(0.0, f64::max);
    let mut worst: f64 = 0.0;
    for (a, b) in bs.iter().zip(&dp) {
        let dq = (a.quaternion - b.quaternion)
            .norm()
            .min((a.quaternion + b.quaternion).norm());
        let errors = [
            (a.position - b.position).norm() / scale_r,
            (a.velocity - b.velocity).norm() / scale_v,
            (a.spin_body - b.spin_body).norm() / scale_w,
            dq,
        ];
        for (what, e) in ["position", "velocity", "spin", "attitude"].iter().zip(errors) {
            assert!(e <= 1e-8, "{what} differs by {e:e} (relative)");
            worst = worst.max(e);
        }
    }
    eprintln!("BS vs Dop853 at rtol 1e-12: largest relative difference of the final state {worst:e}");
}

#[test]
fn spheres_without_dissipation_skip_rotation() {
    let s1 = rock(
        [500.0; 3],
        [-600.0, 0.0, 0.0],
        [0.1, 0.0, 0.0],
        Vec4::w(),
        [0.0, 0.0, 1e-3],
    );
    let s2 = rock(
        [400.0; 3],
        [600.0, 0.0, 0.0],
        [-0.1, 0.0, 0.0],
        Vec4::w(),
        [1e-3, 0.0, 0.0],
    );
    let model = ModelConfig {
        kappa: 5.0,
        inertia: InertiaModel::Gaussian,
        contact_g: G_SI,
    };
    let sys = EllipsoidSystem::new(&[s1.clone(), s2.clone()], model, conservative());
    assert!(!sys.rotation_integrated());
    assert_eq!(sys.dim(), 12);
    // the attitude still turns uniformly about the constant spin, and |ω| is kept
    let y = sys.initial_state();
    let b = sys.bodies_at(100.0, &y);
    assert!((b[0].spin_body.norm() - 1e-3).abs() < 1e-15);
    let angle = 2.0 * b[0].quaternion.w.clamp(-1.0, 1.0).acos();
    assert!((angle - 0.1).abs() < 1e-12, "rotated by {angle}");
    let with_dissipation = Physics {
        dissipation: Some(DissipationTerm { f0: 1.0 }),
        ..conservative()
    };
    let sys2 = EllipsoidSystem::new(&[s1, s2], model, with_dissipation);
    assert!(sys2.rotation_integrated());
    assert_eq!(sys2.dim(), 29);
}

/// A lattice of `counts` rocks 1–2 km in size, spaced so that neighbours are just within reach, with random
/// attitudes, velocities and spins; gravity, contact and dissipation on.
fn rock_lattice(
    rng: &mut Random,
    counts: [usize; 3],
) -> (Vec<rubblepile::ellipsoid::body::Body>, ModelConfig, Physics) {
    let mut bodies = Vec::new();
    for ix in 0..counts[0] {
        for iy in 0..counts[1] {
            for iz in 0..counts[2] {
                let axes = rng.axes(1000.0, 2000.0);
                bodies.push(rock(
                    [axes.x, axes.y, axes.z],
                    [ix as f64 * 4200.0, iy as f64 * 4200.0, iz as f64 * 4200.0],
                    [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)],
                    rng.unit_quaternion(),
                    [rng.range(-1e-3, 1e-3), rng.range(-1e-3, 1e-3), rng.range(-1e-3, 1e-3)],
                ));
            }
        }
    }
    (bodies, ModelConfig::gaussian_si(10.0), Physics::impact(1e-4))
}

/// The right-hand side of a system large enough for every parallel pass (144 bodies, thousands of candidate
/// pairs) has the same bits on 1, 2, 3 and 4 threads (the per-body pair sums of several threads add in the serial
/// scatter's order), and when several threads evaluate the same system at once (the
/// evaluation reuses buffers held by the system; a caller that finds them in use must not disturb another).
#[test]
fn ellipsoid_rhs_bits_do_not_depend_on_threads_or_concurrent_callers() {
    let mut rng = Random::new(78);
    let (bodies, model, physics) = rock_lattice(&mut rng, [6, 6, 4]);
    let system = EllipsoidSystem::new(&bodies, model, physics);
    let y0 = system.initial_state();
    let states: Vec<Vec<f64>> = (0..4)
        .map(|k| {
            y0.iter()
                .enumerate()
                .map(|(i, &v)| {
                    if i % 14 < 3 {
                        v + 150.0 * ((i * 7 + k) % 5) as f64
                    } else {
                        v
                    }
                })
                .collect()
        })
        .collect();
    let eval = |y: &[f64]| {
        let mut d = vec![0.0; y.len()];
        system.rhs(0.0, y, &mut d);
        d.iter().map(|x| x.to_bits()).collect::<Vec<u64>>()
    };
    let on = |threads: usize| -> Vec<Vec<u64>> {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| states.iter().map(|y| eval(y)).collect())
    };
    let reference = on(1);
    assert!(
        system.diagnostics(&states[0]).potential_contact > 0.0,
        "the lattice has contacts"
    );
    for threads in [2, 3, 4] {
        assert_eq!(on(threads), reference, "1 and {threads} threads");
    }
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..3)
            .map(|_| scope.spawn(|| (0..5).flat_map(|_| states.iter().map(|y| eval(y))).collect::<Vec<_>>()))
            .collect();
        for h in handles {
            let got = h.join().unwrap();
            for (k, bits) in got.iter().enumerate() {
                assert_eq!(
                    bits,
                    &reference[k % states.len()],
                    "concurrent caller, state {}",
                    k % states.len()
                );
            }
        }
    });
}

/// From 576 bodies on, the exact gravity's half loop is cut into more than 8 blocks (one per 64 bodies, so that
/// 16 threads have work): the right-hand side of 648 bodies still has the same bits on 1 to 4 threads, and its
/// gravity agrees with the row-wise exact sum of the diagnostics to round-off.
#[test]
fn many_gravity_blocks_keep_the_bits_of_one_thread() {
    assert_eq!(rubblepile::ellipsoid::gravity::blocks(648), 10);
    assert_eq!(
        rubblepile::ellipsoid::gravity::blocks(500),
        8,
        "below 512 bodies: the blocks of every earlier run"
    );
    let mut rng = Random::new(91);
    let (bodies, model, _) = rock_lattice(&mut rng, [9, 9, 8]);
    let gravity_only = Physics {
        gravity: Some(rubblepile::ellipsoid::equations::GravityTerm {
            g: 6.674e-11,
            method: rubblepile::ellipsoid::gravity_tree::GravityMethod::Direct,
        }),
        contact: None,
        dissipation: None,
    };
    let system = EllipsoidSystem::new(&bodies, model, gravity_only);
    let y = system.initial_state();
    let on = |threads: usize| -> Vec<u64> {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let mut d = vec![0.0; y.len()];
        pool.install(|| system.rhs(0.0, &y, &mut d));
        d.iter().map(|x| x.to_bits()).collect()
    };
    let reference = on(1);
    for threads in [2, 3, 4] {
        assert_eq!(on(threads), reference, "1 and {threads} threads");
    }
    // u̇ of body k against −∂U_G/∂r from the row-wise sum (gravity_forces, another order of the same terms)
    let positions: Vec<Vec3> = bodies.iter().map(|b| b.position).collect();
    let masses: Vec<f64> = bodies.iter().map(|b| b.shape.mass).collect();
    let mut rows = vec![Vec3::zeros(); positions.len()];
    rubblepile::ellipsoid::gravity::gravity_forces(6.674e-11, &positions, &masses, &mut rows);
    let stride = y.len() / bodies.len();
    let scale = rows.iter().map(|f| f.norm()).fold(0.0, f64::max);
    for (k, f) in rows.iter().enumerate() {
        let o = k * stride + 7;
        let got = Vec3::new(
            f64::from_bits(reference[o]),
            f64::from_bits(reference[o + 1]),
            f64::from_bits(reference[o + 2]),
        );
        assert!((got - f).norm() <= 1e-12 * scale, "body {k}: {got:?} against {f:?}");
    }
}

/// The Verlet list of candidate pairs is a cache only: along a sequence of states where bodies move less and
/// then far more than the skin (and come back), the RHS of one long-lived system is bit-identical to that of a
/// system built afresh at each state. Guards the cache's validity test and its rebuilds.
#[test]
fn pair_cache_never_changes_the_rhs() {
    let mut rng = Random::new(77);
    let (bodies, model, physics) = rock_lattice(&mut rng, [4, 4, 3]);
    let long_lived = EllipsoidSystem::new(&bodies, model, physics);
    let y0 = long_lived.initial_state();
    let stride = (long_lived.dim() - 1) / bodies.len();
    // displacement of every body by `scale` m in a fixed random direction each
    let dirs: Vec<Vec3> = (0..bodies.len()).map(|_| rng.vec3(1.0).normalize()).collect();
    let moved = |scale: f64| {
        let mut y = y0.clone();
        for (i, d) in dirs.iter().enumerate() {
            for k in 0..3 {
                y[i * stride + k] += scale * d[k];
            }
        }
        y
    };
    let mut contact_energies = Vec::new();
    for scale in [
        0.0, 10.0, 100.0, 400.0, 1500.0, 3000.0, 50.0, 0.0, -2000.0, 6000.0, -9000.0,
    ] {
        let y = moved(scale);
        let mut cached = vec![0.0; y.len()];
        long_lived.rhs(0.0, &y, &mut cached);
        let fresh_system = EllipsoidSystem::new(&bodies, model, physics);
        let mut fresh = vec![0.0; y.len()];
        fresh_system.rhs(0.0, &y, &mut fresh);
        let same = cached.iter().zip(&fresh).all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same, "displacement {scale} m: cached and fresh RHS differ");
        contact_energies.push(long_lived.diagnostics(&y).potential_contact);
    }
    // the states really differ in which pairs touch
    contact_energies.sort_by(f64::total_cmp);
    contact_energies.dedup();
    assert!(contact_energies.len() >= 5, "{contact_energies:?}");
    assert!(contact_energies.iter().all(|&u| u > 0.0), "{contact_energies:?}");
}

/// The pair census (what `bench rhs` reports beside its timings) counts the same pairs as a brute-force pass over
/// all N(N−1)/2 pairs with the overlap exponent `x = κ Δᵀ G⁻¹ Δ` of each: interacting where x lies below the
/// pair's taper end `κλ − ln(cutoff) + 4`, touching where x ≤ κλ (Roig03 Eq. 12). Guards the neighbour
/// search, the cull and the census against dropping or double-counting pairs.
#[test]
fn pair_census_matches_a_brute_force_count_over_all_pairs() {
    use rubblepile::ellipsoid::calibration::lambda;
    use rubblepile::ellipsoid::potential::{BodyGeometry, TAPER_WIDTH, Taper, overlap};
    let mut rng = Random::new(79);
    let (mut bodies, model, physics) = rock_lattice(&mut rng, [5, 5, 4]);
    // squeeze the lattice so that many pairs touch and many more sit inside the taper
    for b in &mut bodies {
        b.position *= 0.6;
    }
    let system = EllipsoidSystem::new(&bodies, model, physics);
    let census = system.pair_census(&system.initial_state());
    let cutoff = physics.contact.unwrap().cutoff;
    let (mut interacting, mut touching) = (0, 0);
    for i in 0..bodies.len() {
        for j in i + 1..bodies.len() {
            let (a, b) = (&bodies[i], &bodies[j]);
            let gi = BodyGeometry::new(&a.shape.axes, &a.quaternion);
            let gj = BodyGeometry::new(&b.shape.axes, &b.quaternion);
            let kl = model.kappa * lambda(a.shape.equivalent_radius(), b.shape.equivalent_radius());
            let taper = Taper::for_pair(cutoff, kl);
            let x = overlap(1.0, model.kappa, &(a.position - b.position), &gi, &gj, &taper).exponent;
            if x < kl - cutoff.ln() + TAPER_WIDTH {
                interacting += 1;
            }
            if x <= kl {
                touching += 1;
            }
        }
    }
    assert_eq!(
        (census.interacting, census.touching),
        (interacting, touching),
        "{census:?}"
    );
    assert!(touching >= 50 && interacting > touching, "{census:?}");
    assert!(census.candidates >= census.exponent_evaluated && census.exponent_evaluated >= census.interacting);
    // no pair term, no census
    let bare = EllipsoidSystem::new(&bodies, model, Physics::default());
    assert_eq!(bare.pair_census(&bare.initial_state()), Default::default());
}

/// The allocation-free right-hand side of spheres under gravity alone (the planetary N-body case) gives
/// ṙ = u/m and u̇ = the pairwise gravity sum.
#[test]
fn gravity_only_spheres_take_the_packed_path_correctly() {
    use rubblepile::ellipsoid::gravity::gravity_forces;
    let mut rng = Random::new(5);
    let bodies: Vec<_> = (0..5)
        .map(|_| {
            let r = rng.range(100.0, 300.0);
            rock(
                [r, r, r],
                rng.vec3(1e5).into(),
                rng.vec3(3.0).into(),
                Vec4::new(0.0, 0.0, 0.0, 1.0),
                [0.0; 3],
            )
        })
        .collect();
    let model = ModelConfig {
        kappa: 10.0,
        inertia: InertiaModel::Gaussian,
        contact_g: G_SI,
    };
    let physics = Physics {
        gravity: Some(GravityTerm::new(G_SI)),
        contact: None,
        dissipation: None,
    };
    let system = EllipsoidSystem::new(&bodies, model, physics);
    assert!(!system.rotation_integrated());
    let y = system.initial_state();
    assert_eq!(y.len(), 6 * bodies.len());
    let mut dy = vec![f64::NAN; y.len()];
    system.rhs(0.0, &y, &mut dy);
    let pos: Vec<Vec3> = bodies.iter().map(|b| b.position).collect();
    let masses: Vec<f64> = bodies.iter().map(|b| b.shape.mass).collect();
    let mut reference = vec![Vec3::zeros(); bodies.len()];
    gravity_forces(G_SI, &pos, &masses, &mut reference);
    for (i, b) in bodies.iter().enumerate() {
        for k in 0..3 {
            assert_eq!(dy[6 * i + k], y[6 * i + 3 + k] / b.shape.mass, "ṙ of body {i}");
            let f = dy[6 * i + 3 + k];
            assert!(
                (f - reference[i][k]).abs() <= 1e-13 * reference[i].norm(),
                "u̇ of body {i}: {f} vs {}",
                reference[i][k]
            );
        }
    }
}
