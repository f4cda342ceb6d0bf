//! Regression: the neighbour list kept across steps (Verlet skin, `stepping.skin_steps`) misses no collision.
//! A run that reuses its list must follow the run that builds a fresh list at every step (`skin_steps = 0`, the
//! reference scheme): same collisions, same states to round-off, no overlap, while building far fewer lists; and runs
//! with different skins give identical bits (the list only decides which pairs are predicted, never how).

mod common;

use rubblepile::granular::hard::stepper::{StepperSettings, System};
use rubblepile::math::Vec3;

/// 300 elastic, rough spheres of radius 0.04 in the unit box under gravity: a dense bottom and a dilute top, as in
/// the model atmosphere, with spin exchange (ε_t = −1) so every velocity component matters.
fn gas(skin_steps: f64) -> System {
    let (ps, walls) = common::hard_sphere_box(11, 300, 2.0);
    let settings = StepperSettings {
        gravity: Some(Vec3::new(0.0, 0.0, -9.81)),
        skin_steps,
        ..Default::default()
    };
    System::new(ps, walls, settings)
}

#[test]
fn reused_neighbour_list_equals_rebuild_every_step() {
    let steps = 300;
    let h = 1e-3;
    let mut reference = gas(0.0);
    let mut runs: Vec<(f64, System)> = [2.0, 4.0, 8.0].into_iter().map(|s| (s, gas(s))).collect();
    for _ in 0..steps {
        reference.step(h).unwrap();
        for (_, sys) in runs.iter_mut() {
            sys.step(h).unwrap();
        }
    }
    let rc = reference.counters;
    assert!(
        rc.pair_collisions > 1000,
        "too few collisions to test: {}",
        rc.pair_collisions
    );
    assert_eq!(
        rc.rebuilds,
        steps + (rc.rebuilds - steps),
        "the reference builds at least once per step"
    );
    assert!(rc.rebuilds >= steps);
    for (skin, sys) in &runs {
        let c = sys.counters;
        let mut dx: f64 = 0.0;
        let mut dv: f64 = 0.0;
        for (p, q) in sys.particles.iter().zip(&reference.particles) {
            dx = dx.max((p.position - q.position).norm());
            dv = dv.max((p.velocity - q.velocity).norm());
        }
        let mut overlap: f64 = 0.0;
        for (a, p) in sys.particles.iter().enumerate() {
            for q in &sys.particles[a + 1..] {
                overlap = overlap.max((p.radius + q.radius - (p.position - q.position).norm()) / p.radius);
            }
        }
        eprintln!(
            "skin {skin}: {} pair + {} wall collisions (reference {} + {}), {} list builds (reference {}), max |dx| {dx:e}, \
             max |dv| {dv:e}, overlap {overlap:e}",
            c.pair_collisions, c.wall_collisions, rc.pair_collisions, rc.wall_collisions, c.rebuilds, rc.rebuilds
        );
        assert_eq!(
            (c.pair_collisions, c.wall_collisions),
            (rc.pair_collisions, rc.wall_collisions),
            "skin {skin}: different collisions"
        );
        assert!(
            dx < 1e-9 && dv < 1e-7,
            "skin {skin}: states differ by {dx:e} m, {dv:e} m/s"
        );
        assert!(overlap < 1e-9, "skin {skin}: overlap {overlap:e}");
        // The list does not change the arithmetic of the predictions, so every skin gives the same bits.
        let (_, first) = &runs[0];
        for (p, q) in sys.particles.iter().zip(&first.particles) {
            assert_eq!(
                (p.position, p.velocity, p.spin),
                (q.position, q.velocity, q.spin),
                "skin {skin} vs 2"
            );
        }
        assert!(
            c.rebuilds * 2 < rc.rebuilds,
            "skin {skin}: {} builds, not fewer than half the reference's {}",
            c.rebuilds,
            rc.rebuilds
        );
    }
}
