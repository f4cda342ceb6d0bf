//! `[sweep]` in campaign files (any field over a list or a grid; the runs are the product) and `analyze-campaign
//! --by FIELD`: the plan's product and order, a swept value equal to the same value written in the file, wrong paths
//! refused naming them, and a tiny swept campaign run and tabulated against its swept field (one row per value, the
//! seeds grouped), with `--at-s` defaulting to the campaign's end.

mod common;
use common::{rubblepile, temp_dir};
use std::path::{Path, PathBuf};

use rubblepile::ellipsoid::output::write_snapshot;
use rubblepile::impact::campaign::parse_campaign;
use rubblepile::impact::target::build_target;

/// A tiny target (6 fragments, 3 → 1.5 km) as in `tests/campaign.rs`, written to `dir/targets/tiny.csv`.
fn tiny_target(dir: &Path) -> PathBuf {
    let mut spec = common::small_pile_spec(1, 6, 3e3, 1.5e3, 0.1);
    spec.f0 = 1e-3;
    let mut quiet = |_: usize, _: f64, _: f64, _: f64| {};
    let (bodies, _) = build_target(&spec, &mut quiet).unwrap();
    std::fs::create_dir_all(dir.join("targets")).unwrap();
    let path = dir.join("targets/tiny.csv");
    write_snapshot(&path, 0.0, &bodies).unwrap();
    path
}

const BASE: &str = r#"
[campaign]
out = "out"
targets = ["targets/tiny.csv"]
projectiles = ["S1"]
angles = [0.0]
seeds = [1, 2]
parallel = 2

[impact]
t_end = 40.0
contact_time = 5.0
every = 5.0
rtol = 1e-8

[[projectile]]
id = "S1"
radius_km = 1.0
speed_km_s = 0.02
"#;

fn plan_error(text: &str, dir: &Path) -> String {
    match parse_campaign(text, "c.toml", dir) {
        Ok(c) => panic!("accepted: {} runs", c.points.len()),
        Err(e) => e.to_string(),
    }
}

#[test]
fn the_plan_is_the_product_in_order_and_a_swept_value_is_the_written_one() {
    let dir = temp_dir("sweep-plan");
    tiny_target(&dir);
    let text = format!(
        "{BASE}\n[sweep]\n\"projectile[0].speed_km_s\" = [0.02, 0.03]\nimpact.f0 = {{ from = 1e-4, to = 3e-4, count = 3 }}\n"
    );
    let c = parse_campaign(&text, "c.toml", &dir).unwrap();
    // 3 f0 (outermost: paths sorted) × 2 speeds × 2 seeds (innermost)
    assert_eq!(c.points.len(), 12);
    let mut k = 0;
    for f0 in [1e-4, 2e-4, 3e-4] {
        for speed in [0.02, 0.03] {
            for seed in [1, 2] {
                let p = &c.points[k];
                assert_eq!(p.name, format!("tiny_S1_z0_s{seed}_f0{f0}_speed_km_s{speed}"));
                assert_eq!(p.seed, seed);
                assert_eq!(p.config.f0, f0);
                assert_eq!(p.config.projectile.speed, speed * 1e3);
                assert_eq!(
                    p.overrides,
                    vec![
                        ("impact.f0".to_string(), format!("{f0}")),
                        ("projectile[0].speed_km_s".to_string(), format!("{speed}")),
                    ]
                );
                k += 1;
            }
        }
    }
    // Q goes as the speed squared (the masses are the same): Q(0.03) / Q(0.02) = 2.25
    let ratio = c.points[2].plan.setup.q_erg_per_g / c.points[0].plan.setup.q_erg_per_g;
    assert!((ratio - 2.25).abs() < 1e-12, "{ratio}");

    // a swept value gives the very run the same value written in [impact] gives (the TOML round trip is exact)
    let swept = parse_campaign(&format!("{BASE}\n[sweep]\n\"impact.every\" = [2.5]\n"), "c.toml", &dir).unwrap();
    let written = parse_campaign(&BASE.replace("every = 5.0", "every = 2.5"), "c.toml", &dir).unwrap();
    assert_eq!(swept.points.len(), written.points.len());
    for (s, w) in swept.points.iter().zip(&written.points) {
        assert_eq!(s.name, format!("{}_every2.5", w.name));
        assert_eq!((&s.config, &s.plan), (&w.config, &w.plan));
    }
    // the grid's own axes by their short names; a step grid of integers; a swept seed list replaces the file's
    let c = parse_campaign(
        &format!("{BASE}\n[sweep]\nseed = {{ from = 3, to = 7, step = 2 }}\nangle = [0, 90]\n"),
        "c.toml",
        &dir,
    )
    .unwrap();
    let names: Vec<&str> = c.points.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "tiny_S1_z0_s3",
            "tiny_S1_z0_s5",
            "tiny_S1_z0_s7",
            "tiny_S1_z90_s3",
            "tiny_S1_z90_s5",
            "tiny_S1_z90_s7"
        ]
    );
    // without [sweep], no override is recorded (campaign.csv keeps its columns)
    let plain = parse_campaign(BASE, "c.toml", &dir).unwrap();
    assert!(plain.points.iter().all(|p| p.overrides.is_empty()));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn wrong_sweep_paths_and_grids_are_refused_naming_them() {
    let dir = temp_dir("sweep-bad");
    tiny_target(&dir);
    let with = |sweep: &str| format!("{BASE}\n[sweep]\n{sweep}\n");
    for (sweep, wanted) in [
        // a mistyped field: named, with the valid ones of its table
        (
            "\"impact.speed\" = [1.0]",
            &["sweep.\"impact.speed\"", "unknown field `speed`", "speed_km_s", "f0"][..],
        ),
        (
            "\"impakt.f0\" = [1.0]",
            &["sweep.\"impakt.f0\"", "unknown field `impakt`", "impact"],
        ),
        ("\"impact.f0\" = [\"x\"]", &["sweep.\"impact.f0\"", "invalid type"]),
        (
            "\"projectile[3].radius_km\" = [1.0]",
            &["sweep.\"projectile[3].radius_km\"", "has 1 entries, so no [3]"],
        ),
        (
            "\"impact.f0\" = { from = 1.0, to = 2.0 }",
            &["sweep.\"impact.f0\"", "one of `step` and `count`"],
        ),
        (
            "\"impact.f0\" = { from = 1.0, to = 2.0, step = -1.0 }",
            &["sweep.\"impact.f0\"", "step"],
        ),
        ("\"impact.f0\" = []", &["sweep.\"impact.f0\"", "at least one value"]),
        (
            "\"impact.f0\" = 3.0",
            &["sweep.\"impact.f0\"", "expected a list of values or a grid"],
        ),
        (
            "\"campaign.out\" = [\"a\"]",
            &["sweep.\"campaign.out\"", "not a field of a run"],
        ),
        // a value the impact refuses: the field, and which swept values gave it
        (
            "\"impact.t_end\" = [40.0, -1.0]",
            &["impact.t_end", "with the sweep's impact.t_end = -1"],
        ),
    ] {
        let e = plan_error(&with(sweep), &dir);
        assert_eq!(e.lines().count(), 1, "{e}");
        for w in wanted {
            assert!(e.contains(w), "{sweep}: {e:?} lacks {w:?}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let mut r = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let header = r.headers().unwrap().iter().map(String::from).collect();
    let rows = r
        .records()
        .map(|x| x.unwrap().iter().map(String::from).collect())
        .collect();
    (header, rows)
}

#[test]
fn a_swept_campaign_runs_and_is_tabulated_against_its_field() {
    let dir = temp_dir("sweep-run");
    tiny_target(&dir);
    let text = format!("{BASE}\n[sweep]\n\"projectile[0].speed_km_s\" = [0.02, 0.03]\n");
    std::fs::write(dir.join("c.toml"), text).unwrap();
    let run = rubblepile(&dir, &["campaign", "c.toml", "--no-progress"]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    // campaign.csv: the fixed columns, then the swept path, with each run's value
    let (header, rows) = read_csv(&dir.join("out/campaign.csv"));
    assert_eq!(header.last().unwrap(), "projectile[0].speed_km_s");
    assert_eq!(rows.len(), 4);
    assert!(rows.iter().all(|r| r[6] == "completed"), "{rows:?}");
    let speeds: Vec<&str> = rows.iter().map(|r| r[header.len() - 1].as_str()).collect();
    assert_eq!(speeds, ["0.02", "0.02", "0.03", "0.03"]);

    // no --at-s: the campaign's end (40 s); no --by: its one swept field
    let out = rubblepile(&dir, &["analyze-campaign", "out"]);
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    );
    assert!(out.status.success(), "{stderr}");
    assert!(stdout.contains("campaign analysis at t = 40 s"), "{stdout}");
    assert!(stdout.contains("outcomes against projectile[0].speed_km_s"), "{stdout}");
    // two Q values: Q*_D (if any) comes with the warning
    if stdout.contains("bootstrap 95 % interval") {
        assert!(
            stderr.contains("warning: Q*_D") && stderr.contains("fewer than three"),
            "{stderr}"
        );
    }
    let table = dir.join("out/analysis/campaign_by_projectile_0__speed_km_s.csv");
    let (th, trows) = read_csv(&table);
    assert_eq!(th[0], "projectile[0].speed_km_s");
    assert_eq!(th[1], "runs", "no other field varies: {th:?}");
    assert_eq!(trows.len(), 2, "one row per speed: {trows:?}");
    assert_eq!((trows[0][0].as_str(), trows[1][0].as_str()), ("0.02", "0.03"));
    // each row: the two seeds' runs, their values as campaign_runs.csv has them, mean and standard error of those
    let (rh, runs) = read_csv(&dir.join("out/analysis/campaign_runs.csv"));
    let rc = |name: &str| rh.iter().position(|h| h == name).unwrap();
    let tc = |name: &str| th.iter().position(|h| h == name).unwrap();
    for (row, speed) in trows.iter().zip(["0.02", "0.03"]) {
        assert_eq!(row[tc("runs")], "2");
        for metric in ["bound_mass_fraction", "largest_remnant_fraction", "fragments"] {
            let mut expected: Vec<f64> = runs
                .iter()
                .filter(|r| r[rc("run")].ends_with(&format!("_speed_km_s{speed}")))
                .map(|r| r[rc(metric)].parse().unwrap())
                .collect();
            let mut values: Vec<f64> = row[tc(&format!("{metric}_values"))]
                .split(';')
                .map(|v| v.parse().unwrap())
                .collect();
            expected.sort_by(f64::total_cmp);
            values.sort_by(f64::total_cmp);
            assert_eq!(values, expected, "{metric} at {speed}");
            let mean: f64 = row[tc(&format!("{metric}_mean"))].parse().unwrap();
            let m = (expected[0] + expected[1]) / 2.0;
            assert!((mean - m).abs() <= 1e-12 * m.abs().max(1.0), "{metric}: {mean} vs {m}");
            // s/√n for two values is |a − b| / 2
            let se: f64 = row[tc(&format!("{metric}_se"))].parse().unwrap();
            let want = (expected[1] - expected[0]).abs() / 2.0;
            assert!(
                (se - want).abs() <= 1e-12 * want.max(1e-300) + 1e-15,
                "{metric}: {se} vs {want}"
            );
        }
    }
    let svg = std::fs::read_to_string(dir.join("out/analysis/campaign_by_projectile_0__speed_km_s.svg")).unwrap();
    assert!(svg.contains("mass fraction (dimensionless)") && svg.contains("projectile[0].speed_km_s"));

    // --by another field: Q, one row per speed again (each speed one Q)
    let out = rubblepile(&dir, &["analyze-campaign", "out", "--force", "--by", "q"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (_, qrows) = read_csv(&dir.join("out/analysis/campaign_by_q_erg_per_g.csv"));
    assert_eq!(qrows.len(), 2);
    // a field the campaign lacks, a target it lacks: one line naming the flag and the valid names
    for (args, wanted) in [
        (
            &["--by", "speed"][..],
            &["--by", "`speed`", "projectile[0].speed_km_s", "angle_deg"][..],
        ),
        (&["--spin-target", "N200_T12"], &["--spin-target", "N200_T12", "tiny"]),
    ] {
        let mut all = vec!["analyze-campaign", "out", "--force"];
        all.extend_from_slice(args);
        let bad = rubblepile(&dir, &all);
        assert_eq!(bad.status.code(), Some(2));
        let e = String::from_utf8_lossy(&bad.stderr);
        assert_eq!(e.trim().lines().count(), 1, "{e}");
        for w in wanted {
            assert!(e.contains(w), "{e:?} lacks {w:?}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs ending at different times: no default `--at-s`, and the error says so.
#[test]
fn runs_ending_at_different_times_need_at() {
    let dir = temp_dir("sweep-ends");
    tiny_target(&dir);
    let text = format!("{BASE}\n[sweep]\n\"impact.t_end\" = [20.0, 40.0]\n").replace("seeds = [1, 2]", "seeds = [1]");
    std::fs::write(dir.join("c.toml"), text).unwrap();
    let run = rubblepile(&dir, &["campaign", "c.toml", "--no-progress"]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let bad = rubblepile(&dir, &["analyze-campaign", "out"]);
    assert_eq!(bad.status.code(), Some(2));
    let e = String::from_utf8_lossy(&bad.stderr);
    assert!(
        e.contains("--at-s: the runs end at different times ([20.0, 40.0] s)"),
        "{e}"
    );
    // at a time both have a snapshot (t_end of each, and the default snapshots cut at t_end: 0, 20; 0, 40) —
    // t = 20 s is the shorter run's end but not a snapshot of the longer: named
    let bad = rubblepile(&dir, &["analyze-campaign", "out", "--at-s", "20"]);
    assert_eq!(bad.status.code(), Some(2), "{}", String::from_utf8_lossy(&bad.stderr));
    let _ = std::fs::remove_dir_all(&dir);
}

/// The oblique-impact keys of `[impact]` are swept like any other field (no code of their own): θ = 0° and 30°
/// become two runs aimed at the centre and at θ (45° misses this lumpy six-fragment pile: the plan refuses it,
/// naming the field), and a sweep of `impact_parameter_frac` beside a fixed
/// `impact_angle_deg` is refused as two aims, naming both.
#[test]
fn oblique_impact_fields_are_swept_without_code_of_their_own() {
    use rubblepile::impact::geometry::Aim;
    let dir = temp_dir("sweep-oblique");
    tiny_target(&dir);
    let text = format!("{BASE}\n[sweep]\nimpact.impact_angle_deg = [0.0, 30.0]\n");
    let c = parse_campaign(&text, "c.toml", &dir).unwrap();
    assert_eq!(c.points.len(), 4);
    assert_eq!(c.points[0].config.geometry.aim, Aim::AngleDeg(0.0));
    assert_eq!(c.points[2].config.geometry.aim, Aim::AngleDeg(30.0));
    assert!(
        c.points[2].name.ends_with("_impact_angle_deg30"),
        "{}",
        c.points[2].name
    );
    let miss = plan_error(&format!("{BASE}\n[sweep]\nimpact.impact_angle_deg = [45.0]\n"), &dir);
    assert!(
        miss.contains("impact.impact_angle_deg") && miss.contains("misses the target"),
        "{miss}"
    );
    let both = BASE.replace("[impact]\n", "[impact]\nimpact_angle_deg = 30.0\n")
        + "\n[sweep]\nimpact.impact_parameter_frac = [0.5]\n";
    let e = plan_error(&both, &dir);
    assert!(
        e.contains("impact_angle_deg") && e.contains("impact_parameter_frac"),
        "{e}"
    );
}
