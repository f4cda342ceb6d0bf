//! The quick stability suite (`rubblepile bench stability --quick`, cases in [`super::cases`]) and the
//! contact-barrier detector end to end (Roig03 Eqs. 13–14): the 3× head-on impact must be reported naming
//! bodies 1 and 2, the calibrated one must not; θ = 0 keeps `||q| − 1|` below 1e-9; F0 = 100 keeps
//! `H − H0 − 2∫F` below 1e-6; κ = 1.6 and κ = 50 complete; no quick case fails. `tests/stability.rs` runs the
//! command-line side.

use std::path::Path;

use super::cases::{QUATERNION_HARD, RTOL, all_cases};
use super::suite::{CaseResult, Verdict, run_case};
use crate::test_dirs::temp_dir;
use rubblepile::driver::{RunError, RunOptions, resume_run, run_scene};
use rubblepile::ellipsoid::barrier::OVERRUN_FILE;
use rubblepile::ellipsoid::scene::parse_scene;
use rubblepile::integrate::Method;

/// Whether case `id` is named by `prefix`: the id itself, or its part before a `-`.
fn named(id: &str, prefix: &str) -> bool {
    id == prefix || id.starts_with(&format!("{prefix}-"))
}

/// Runs the quick cases named by `prefixes`, printing their rows.
fn run(prefixes: &[&str]) -> Vec<CaseResult> {
    let dir = temp_dir("stability");
    let out: Vec<CaseResult> = all_cases(true)
        .iter()
        .filter(|c| prefixes.iter().any(|p| named(&c.id, p)))
        .map(|c| run_case(c, &dir, false).unwrap_or_else(|e| panic!("{}: {e}", c.id)))
        .collect();
    assert_eq!(out.len(), prefixes.len(), "every prefix names one case");
    for r in &out {
        eprintln!("{} {}: {}", r.row.case, r.row.verdict.as_str(), r.row.note);
    }
    out
}

fn case<'a>(results: &'a [CaseResult], id: &str) -> &'a CaseResult {
    results.iter().find(|r| named(&r.row.case, id)).expect("case ran")
}

#[test]
fn head_on_overrun_is_reported_for_the_right_pair_and_only_above_the_calibrated_speed() {
    let results = run(&["a1", "a2", "a3"]);
    for r in &results {
        assert_eq!(r.row.verdict, Verdict::Pass, "{}: {}", r.row.case, r.row.note);
    }
    // At the calibrated speed: completed, no overrun, no log file.
    let a1 = &case(&results, "a1").run;
    assert!(a1.completed());
    let b1 = a1.summary.barrier.as_ref().expect("contact on: barrier report");
    assert_eq!((b1.overrun_pairs, b1.samples), (0, 0));
    assert!(!a1.dir.join(OVERRUN_FILE).exists());
    assert!(a1.summary.warnings().is_empty());

    // 3x: completed, exactly the pair (1, 2), at about 15 m/s, against the calibrated 5 m/s.
    let a2 = &case(&results, "a2").run;
    assert!(a2.completed());
    let b2 = a2.summary.barrier.as_ref().unwrap();
    assert_eq!(b2.overrun_pairs, 1);
    let p = &b2.pairs[0];
    assert_eq!((p.i, p.j, p.broke_through), (1, 2, false));
    assert!((p.worst_speed / 15.0 - 1.0).abs() < 0.05, "{}", p.worst_speed);
    assert!((p.calibrated_speed / 5.0 - 1.0).abs() < 1e-9, "{}", p.calibrated_speed);
    let w = a2.summary.warnings();
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with(&format!(
            "bodies 1 and 2 overran the contact barrier at t = {} s",
            p.first_t
        )),
        "{}",
        w[0]
    );
    assert!(w[0].contains("> calibrated 5.0000 m/s"), "{}", w[0]);
    // The log has one row per overrun sample, all for the pair (1, 2).
    let log = std::fs::read_to_string(a2.dir.join(OVERRUN_FILE)).unwrap();
    let rows: Vec<&str> = log.lines().skip(1).collect();
    assert_eq!(rows.len() as u64, b2.samples);
    assert!(
        rows.iter()
            .all(|r| r.split(',').nth(1) == Some("1") && r.split(',').nth(2) == Some("2"))
    );

    // 15x: the pair breaks through; the run stops at the point-mass singularity with a message naming it,
    // never with silent interpenetration or NaN in a "completed" run.
    let a3 = &case(&results, "a3").run;
    let b3 = a3.summary.barrier.as_ref().unwrap();
    assert_eq!((b3.pairs[0].i, b3.pairs[0].j, b3.pairs[0].broke_through), (1, 2, true));
    let cause = a3.failure.as_deref().expect("stops at the singularity");
    assert!(
        cause.contains("after bodies 1 and 2 broke through the contact barrier"),
        "{cause}"
    );
    assert!(a3.summary.warnings()[0].contains("broke through"));
}

#[test]
fn resumed_run_keeps_the_overruns_found_before_the_checkpoint() {
    let scene_text = all_cases(true)
        .into_iter()
        .find(|c| named(&c.id, "a2"))
        .unwrap()
        .scene_toml;
    let scene = parse_scene(&scene_text, "a2.toml", None).unwrap();
    let dir = temp_dir("stability-resume");
    let quiet = RunOptions {
        progress: false,
        checkpoint_every: None,
        ..RunOptions::default()
    };
    let whole = run_scene(&scene, &dir.join("whole"), &quiet).unwrap();
    // Stop after a checkpoint at t ≈ 100 s, in the middle of the overrun (contact from ≈ 54 s to ≈ 210 s).
    let stopping = RunOptions {
        checkpoint_every_sim: Some(100.0),
        stop_after_checkpoints: Some(1),
        ..quiet
    };
    match run_scene(&scene, &dir.join("split"), &stopping) {
        Err(RunError::Stopped { t, .. }) => assert!((90.0..150.0).contains(&t), "stopped at {t}"),
        other => panic!("expected a stop after the checkpoint, got {other:?}"),
    }
    let resumed = resume_run(&dir.join("split"), &quiet).unwrap();
    assert_eq!(resumed.barrier, whole.barrier);
    assert!(whole.barrier.as_ref().unwrap().samples > 5);
    let read = |p: &Path| std::fs::read_to_string(p.join(OVERRUN_FILE)).unwrap();
    assert_eq!(read(&dir.join("split")), read(&dir.join("whole")));
}

#[test]
fn theta_zero_keeps_the_quaternion_norm_and_the_analytic_top() {
    let results = run(&["d0", "d1", "d2"]);
    for r in &results {
        assert_eq!(r.row.verdict, Verdict::Pass, "{}: {}", r.row.case, r.row.note);
        // the stated bound: |q| drifts by at most rtol per accepted step, and never near the driver's stop
        let q = r.row.max_quat_norm_error;
        assert!(
            q <= RTOL * r.row.steps as f64,
            "{}: {q:e} after {} steps",
            r.row.case,
            r.row.steps
        );
        assert!(q <= QUATERNION_HARD, "{}: {q:e}", r.row.case);
    }
    // θ = 0 is not special: no worse than the same top at a generic attitude
    let (d0, d1) = (case(&results, "d0"), case(&results, "d1"));
    assert!(
        d1.row.max_quat_norm_error <= 10.0 * d0.row.max_quat_norm_error.max(RTOL),
        "theta = 0: {:e}, generic: {:e}",
        d1.row.max_quat_norm_error,
        d0.row.max_quat_norm_error
    );
}

#[test]
fn stiff_dissipation_keeps_the_energy_bookkeeping_and_does_not_stall() {
    for r in run(&["e1", "e2"]) {
        assert_ne!(r.row.verdict, Verdict::Fail, "{}: {}", r.row.case, r.row.note);
        assert!(r.run.completed());
        // H − H0 − 2∫F relative to the initial energy scale
        assert!(r.row.energy_error <= 1e-6, "{}: {:e}", r.row.case, r.row.energy_error);
        assert!(r.row.steps + r.row.rejections <= 1_000_000, "{}", r.row.steps);
        assert!(r.run.summary.physics.dissipation.unwrap().f0 == 100.0);
        // the point dissipation function conserves both momenta (Roig03 Appendix A), sticking or not
        let s = &r.run.summary;
        assert!(
            s.linear_momentum_error <= 1e-8,
            "{}: |dP| {:e}",
            r.row.case,
            s.linear_momentum_error
        );
        assert!(
            s.angular_momentum_error <= 1e-8,
            "{}: |dL| {:e}",
            r.row.case,
            s.angular_momentum_error
        );
    }
}

#[test]
fn kappa_from_1_6_to_50_completes_and_the_detector_follows_the_calibration() {
    let results = run(&["f-kappa-1.6", "f-kappa-5", "f-kappa-50"]);
    for r in &results {
        assert_eq!(r.row.verdict, Verdict::Pass, "{}: {}", r.row.case, r.row.note);
        assert!(r.run.completed());
        assert!(r.row.energy_error <= 1e-8, "{}: {:e}", r.row.case, r.row.energy_error);
    }
    // 0.8 m/s is far above κ = 1.6's calibrated speed and far below κ = 50's.
    assert_eq!(case(&results, "f-kappa-1.6").run.overrun_pairs(), 1);
    assert_eq!(case(&results, "f-kappa-50").run.overrun_pairs(), 0);
    assert!((case(&results, "f-kappa-50").run.summary.kappa - 50.0).abs() < 1e-9);
}

#[test]
fn remaining_quick_cases_do_not_fail() {
    let results = run(&["b1", "b2", "c1", "c2", "g1", "g2", "h1", "h2"]);
    for r in &results {
        assert_eq!(r.row.verdict, Verdict::Pass, "{}: {}", r.row.case, r.row.note);
    }
    // the naive calibration of the collapsing cloud is caught by the detector, the proper one is not
    assert!(case(&results, "g1").run.overrun_pairs() > 0);
    assert_eq!(case(&results, "g2").run.overrun_pairs(), 0);
}

/// `bench stability --method`: every case's scene runs with the method asked for, its tolerances unchanged.
#[test]
fn stability_cases_take_another_method() {
    for case in all_cases(true) {
        let before = case.scene_toml.clone();
        let id = case.id.clone();
        let after = case.with_method(Method::BulirschStoerImplicit).scene_toml;
        assert!(before.contains("method = \"bulirsch-stoer\"\n"), "{id}: no method line");
        assert!(
            after.contains("method = \"bulirsch-stoer-implicit\"\n"),
            "{id}: method not replaced"
        );
        assert_eq!(
            after.replace(
                "method = \"bulirsch-stoer-implicit\"\n",
                "method = \"bulirsch-stoer\"\n"
            ),
            before,
            "{id}: more than the method line changed"
        );
    }
}
