//! `report zhang2017` with `--full`: a full-size run still going is read as far as it has got (status, simulated
//! time against the scene's t_end, wall time so far from `timeseries.csv`, residuals so far), next to the
//! scaled runs' Table 3.

use crate::studies::zhang2017::report::{ReportSources, write_report};
use rubblepile::analysis::spinup_diagnostics::{SPINUP_HEADER, SpinupSample};
use std::path::Path;

/// Writes a path-2 run directory: `samples` every 200 s up to `t_last`, one snapshot of `n` spheres, a scene
/// with `t_end`, and a time series whose wall clock reads `wall` at the end; `summary` if finished.
fn fake_run(dir: &Path, n: usize, t_last: f64, t_end: f64, wall: f64, finished: bool) {
    fake_run_at(dir, "path2", n, t_last, t_end, wall, finished, None);
}

/// [`fake_run`] into `dir/path`; with `shed_below`, b/a drops by 0.02 once the period (5 h falling to 3 h) is below it
/// (T_c,1 there).
#[allow(clippy::too_many_arguments)]
fn fake_run_at(
    dir: &Path,
    path: &str,
    n: usize,
    t_last: f64,
    t_end: f64,
    wall: f64,
    finished: bool,
    shed_below: Option<f64>,
) {
    let run = dir.join(path);
    std::fs::create_dir_all(run.join("snapshots")).unwrap();
    let mut csv = SPINUP_HEADER.to_string();
    let mut ts = "t,step,energy_residual,angular_momentum_error,max_overlap_fraction,wall_seconds\n".to_string();
    let mut t = 0.0;
    while t <= t_last {
        let period = 5.0 - 2.0 * t / 38300.0;
        let b = if shed_below.is_some_and(|p| period < p) {
            382.0
        } else {
            390.0
        };
        let s = SpinupSample {
            t,
            path_period_h: period,
            period_h: period,
            forcing: true,
            body_particles: n,
            body_mass_fraction: 1.0,
            a: 400.0,
            b,
            c: 350.0,
            b_over_a: b / 400.0,
            c_over_a: 0.875,
            packing_fraction: 0.74,
            interior_particles: n / 2,
            coordination_number: 9.0,
            fraction_0_contacts: 0.0,
            fraction_1_contact: 0.0,
            rves: 10,
            s_max: 1.0,
            p_max: 2.0,
            theta_max_deg: 20.0,
            coordination_loaded: 8.5,
        };
        csv += &s.csv_row();
        ts += &format!(
            "{t},{},{},2e-5,{},{}\n",
            (t / 0.66) as u64,
            1e-3 * t / t_last,
            3e-3,
            wall * t / t_last
        );
        t += 200.0;
    }
    std::fs::write(run.join("spinup.csv"), csv).unwrap();
    std::fs::write(run.join("timeseries.csv"), ts).unwrap();
    let mut snap = "t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz\n".to_string();
    for k in 0..n {
        snap += &format!("0,{k},1e7,10.0,{},0,0,0,0,0,0,0,0\n", 20.0 * k as f64);
    }
    std::fs::write(run.join("snapshots/0.csv"), snap).unwrap();
    std::fs::write(
        run.join("scene.toml"),
        format!("[scene]\nt_end = {t_end:.1}\n\n[spinup]\nt_start = 700.0\n"),
    )
    .unwrap();
    if finished {
        std::fs::write(
            run.join("summary.json"),
            format!("{{\"status\": \"completed\", \"wall_seconds\": {wall}, \"max_overlap_fraction\": 0.004}}"),
        )
        .unwrap();
    }
}

#[test]
fn full_size_section_reads_a_run_still_going() {
    let root = std::env::temp_dir().join(format!("rp_report_full_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    fake_run(&root.join("runs/hcp"), 30, 38300.0, 38300.0, 600.0, true);
    fake_run(&root.join("full/hcp"), 50, 12000.0, 38300.0, 9000.0, false);
    let out = root.join("out");
    let report = write_report(
        &ReportSources {
            full: Some(&root.join("full")),
            ..ReportSources::new(&root.join("runs"))
        },
        &out,
        false,
    )
    .unwrap();
    let md = std::fs::read_to_string(&report).unwrap();
    let section = &md[md.find("## Full size").expect("a full-size section")..];
    let row = section
        .lines()
        .find(|l| l.starts_with("| HCP |"))
        .expect("the full-size row");
    println!("{row}");
    assert!(row.contains("| 50 |"), "N: {row}");
    assert!(row.contains("running"), "status: {row}");
    assert!(row.contains("| 12000 / 38300 |"), "simulated / t_end: {row}");
    assert!(row.contains("| 9000 |"), "wall so far: {row}");
    assert!(row.contains("1.0e-3 / 2.0e-5 (so far)"), "residuals so far: {row}");
    assert!(out.join("fig5_hcp_full.svg").is_file() || out.join("fig5_hcp_full.png").is_file());
    // the command line written into the report names --full, and a second write needs force
    assert!(md.contains("--full "), "{}", &md[..400]);
    assert!(
        write_report(
            &ReportSources {
                full: Some(&root.join("full")),
                ..ReportSources::new(&root.join("runs"))
            },
            &out,
            false
        )
        .is_err()
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// The hand-written `NOTES.md` in the output directory is appended verbatim at the end of REPORT.md (the hook
/// shared with the Richardson11 report, `studies::report_notes`); without it the report ends with the figures.
/// A `critical.json` that records T_c,3 by both creep criteria adds a section with both beside Table 3; one from
/// before the paper's criterion came in (only the top-level T_c,3) adds nothing.
#[test]
fn notes_are_appended_verbatim_and_both_creep_verdicts_are_shown() {
    let root = std::env::temp_dir().join(format!("rp_report_notes_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    fake_run(&root.join("runs/hcp"), 30, 38300.0, 38300.0, 600.0, true);
    let crit = root.join("runs/hcp/critical");
    std::fs::create_dir_all(&crit).unwrap();
    std::fs::write(
        crit.join("critical.json"),
        r#"{"t_c3_hours": 2.64, "friction_angle_deg": 45.2, "runs": []}"#,
    )
    .unwrap();
    let out = root.join("out");
    let md = report_of_runs(&root);
    assert!(
        !md.contains("by creep criterion"),
        "old critical.json: no criterion section"
    );
    assert!(
        md.trim_end().ends_with("![fig5_hcp](fig5_hcp.png)"),
        "{}",
        &md[md.len() - 200..]
    );
    let notes = "## Paper vs ours (hand-written)\n\n| item | paper | ours | verdict |\n| --- | --- | --- | --- |\n\
                 | Table 3 HCP T_c3 | 2.40 h | 2.64 h | not |\n";
    std::fs::write(out.join("NOTES.md"), notes).unwrap();
    std::fs::write(
        crit.join("critical.json"),
        r#"{"t_c3_hours": 2.70, "friction_angle_deg": 44.0, "runs": [],
            "paper": {"t_c3_hours": 2.70, "friction_angle_deg": 44.0},
            "ours": {"t_c3_hours": 2.64, "friction_angle_deg": 45.2}}"#,
    )
    .unwrap();
    let md2 =
        std::fs::read_to_string(write_report(&ReportSources::new(&root.join("runs")), &out, true).unwrap()).unwrap();
    assert!(md2.ends_with(&format!("\n\n{notes}\n")), "{}", &md2[md2.len() - 300..]);
    let section = &md2[md2.find("## T_c,3 by creep criterion").expect("criterion section")..];
    let row = section.lines().find(|l| l.starts_with("| HCP |")).expect("HCP row");
    assert_eq!(row, "| HCP | 2.70, 44.0 | 2.64, 45.2 | 2.40, 43 |");
    let _ = std::fs::remove_dir_all(&root);
}

/// The committed `analysis/zhang2017/REPORT.md` ends with the committed `NOTES.md` exactly as the generator
/// appends it (its tally marker replaced by the counted tally), so that the hand-written part and the report
/// cannot drift apart between regenerations.
#[test]
fn committed_report_ends_with_the_committed_notes() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("analysis/zhang2017");
    let report = std::fs::read_to_string(dir.join("REPORT.md")).unwrap();
    let notes = std::fs::read_to_string(dir.join("NOTES.md")).unwrap();
    let mut expected = String::new();
    crate::studies::report_notes::append_notes(&mut expected, &dir);
    assert_eq!(
        expected,
        format!("\n{}\n", crate::studies::report_notes::with_tally(&notes))
    );
    assert!(
        notes.contains(crate::studies::report_notes::TALLY_MARKER),
        "NOTES.md's tally is computed, not typed"
    );
    assert!(
        report.ends_with(&expected),
        "REPORT.md does not end with NOTES.md as appended"
    );
}

/// `--paths`: the paths section shows paths 1 and 3 from their own directory and path 2 from the Table 3 runs, each
/// with its own T_c,1, beside the paper's Table 6 for HCP.
#[test]
fn paths_section_sets_the_three_paths_beside_table_6() {
    let root = std::env::temp_dir().join(format!("rp_report_paths_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    fake_run_at(
        &root.join("runs/hcp"),
        "path2",
        30,
        38300.0,
        38300.0,
        600.0,
        true,
        Some(3.6),
    );
    fake_run_at(
        &root.join("paths/hcp"),
        "path1",
        30,
        38300.0,
        38300.0,
        700.0,
        true,
        Some(3.3),
    );
    fake_run_at(
        &root.join("paths/hcp"),
        "path3",
        30,
        20000.0,
        38300.0,
        300.0,
        false,
        Some(4.2),
    );
    fake_run_at(
        &root.join("paths/hcp_rho2309"),
        "path3",
        30,
        38300.0,
        38300.0,
        300.0,
        true,
        Some(4.0),
    );
    // a T_c,3 search on path 3 only
    let crit = root.join("paths/hcp/critical_path3");
    std::fs::create_dir_all(&crit).unwrap();
    std::fs::write(
        crit.join("critical.json"),
        r#"{"t_c3_hours": 2.52, "friction_angle_deg": 44.0, "runs": [],
            "paper": {"t_c3_hours": 2.52, "friction_angle_deg": 44.0},
            "ours": {"t_c3_hours": 2.48, "friction_angle_deg": 46.0}}"#,
    )
    .unwrap();
    let out = root.join("out");
    let md = std::fs::read_to_string(
        write_report(
            &ReportSources {
                paths: Some(&root.join("paths")),
                ..ReportSources::new(&root.join("runs"))
            },
            &out,
            false,
        )
        .unwrap(),
    )
    .unwrap();
    assert!(md.contains("--paths "), "{}", &md[..400]);
    let section = &md[md.find("## Spin-up paths").expect("a paths section")..];
    let rows: Vec<&str> = section.lines().filter(|l| l.starts_with("| HCP |")).collect();
    assert_eq!(rows.len(), 3, "{section}");
    // the first sample below the shedding period: 5 - 2 t / 38300 sampled every 200 s
    let first_below = |p: f64| {
        let mut t: f64 = 0.0;
        while 5.0 - 2.0 * t / 38300.0 >= p {
            t += 200.0;
        }
        format!("| {:.3} |", 5.0 - 2.0 * t / 38300.0)
    };
    for (row, (path, shed, paper)) in rows.iter().zip([
        ("| 1 |", 3.3, "2.38 / 2.36 / 2.40 (Table 6)"),
        ("| 2 |", 3.6, "2.30 / 2.27 / 2.40 (Table 6)"),
        ("| 3 |", 4.2, "2.26 / 2.26 / 2.40 (Table 6)"),
    ]) {
        assert!(row.contains(path), "{row}");
        assert!(row.contains(&first_below(shed)), "T_c1 of {path}: {row}");
        assert!(row.contains(paper), "{row}");
    }
    assert!(rows[2].contains("running"), "path 3 still going: {}", rows[2]);
    assert!(rows[2].contains("| 2.52 / 2.48 |"), "path 3's T_c,3: {}", rows[2]);
    assert!(
        rows[0].contains("| – (not searched) |"),
        "path 1 has no search: {}",
        rows[0]
    );
    // a density variant of HCP is set beside its own Table 6 row
    let variant = section
        .lines()
        .find(|l| l.starts_with("| HCP_RHO2309 | 3 |"))
        .expect("the 2309 kg/m³ variant's path 3");
    assert!(variant.contains("2.26 / 2.26 / 2.29 (Table 6)"), "{variant}");
    let _ = std::fs::remove_dir_all(&root);
}

/// `--ladder`: one row per rung, by model and then by grain count; a compact rung (no snapshots, `particles.json`
/// instead) gives its grains, radius and mass from that file; of two searches the finer one that found T_c,3 is
/// shown; each model's rows are closed by the paper's row at its Table 2 grain count, and the three figures (T_c,3,
/// φ, T_c,1/T_c,2) carry each model's paper value.
#[test]
fn ladder_section_takes_compact_rungs_and_the_finest_search() {
    let root = std::env::temp_dir().join(format!("rp_report_ladder_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    fake_run(&root.join("runs/rcp"), 30, 38300.0, 38300.0, 600.0, true);
    fake_run_at(
        &root.join("ladder/rcp_big"),
        "path2",
        80,
        38300.0,
        38300.0,
        900.0,
        true,
        Some(2.6),
    );
    fake_run_at(
        &root.join("ladder/rcp_small"),
        "path2",
        40,
        38300.0,
        38300.0,
        300.0,
        true,
        Some(2.5),
    );
    // the big rung as a compact copy: the first snapshot replaced by its summary
    let big = root.join("ladder/rcp_big/path2");
    std::fs::remove_dir_all(big.join("snapshots")).unwrap();
    std::fs::write(
        big.join("particles.json"),
        r#"{"n": 80, "radius_min_m": 6.5, "radius_max_m": 6.5, "mass_kg": 8e8}"#,
    )
    .unwrap();
    let search = |dir: &str, t: &[f64], t_c3: Option<f64>| {
        let d = root.join(dir);
        std::fs::create_dir_all(&d).unwrap();
        let runs: Vec<String> = t.iter().map(|x| format!("{{\"t_final_hours\": {x}}}")).collect();
        let t_c3 = t_c3.map_or("null".to_string(), |x| x.to_string());
        std::fs::write(
            d.join("critical.json"),
            format!(
                "{{\"t_c3_hours\": {t_c3}, \"friction_angle_deg\": 50.0, \"runs\": [{}], \
                 \"paper\": {{\"t_c3_hours\": {t_c3}, \"friction_angle_deg\": 50.0}}, \
                 \"ours\": {{\"t_c3_hours\": 2.61, \"friction_angle_deg\": 48.0}}}}",
                runs.join(",")
            ),
        )
        .unwrap();
    };
    search("ladder/rcp_big/critical", &[2.5, 2.55, 2.6], Some(2.55));
    search("ladder/rcp_big/critical_fine", &[2.51, 2.52, 2.53], Some(2.52));
    search("ladder/rcp_small/critical", &[2.5, 2.55], None);
    // a rung of another model in the same ladder
    fake_run_at(
        &root.join("ladder/hcp_full"),
        "path2",
        120,
        38300.0,
        38300.0,
        1200.0,
        true,
        Some(2.5),
    );
    search("ladder/hcp_full/critical", &[2.5, 2.55, 2.6], Some(2.6));
    let out = root.join("out");
    let md = std::fs::read_to_string(
        write_report(
            &ReportSources {
                ladder: Some(&root.join("ladder")),
                ..ReportSources::new(&root.join("runs"))
            },
            &out,
            false,
        )
        .unwrap(),
    )
    .unwrap();
    let section = &md[md.find("## Resolution ladder").expect("a ladder section")..];
    let rows: Vec<&str> = section.lines().filter(|l| l.starts_with("| rcp_")).collect();
    println!("{}", rows.join("\n"));
    assert_eq!(rows.len(), 2, "{section}");
    assert!(rows[0].starts_with("| rcp_small | 40 | 10.00 |"), "{}", rows[0]);
    assert!(
        rows[1].starts_with("| rcp_big | 80 | 6.50 |"),
        "grains and radius from particles.json: {}",
        rows[1]
    );
    assert!(
        rows[1].contains("| 2.52 h, 50.0° |"),
        "the fine search's T_c3: {}",
        rows[1]
    );
    assert!(rows[1].contains("`critical_fine`: 0.01 h, 3"), "{}", rows[1]);
    assert!(
        rows[0].contains("| – h, 50.0° |"),
        "no T_c3 found by the paper's criterion: {}",
        rows[0]
    );
    assert!(section.contains("| paper (RCP) | 36 523 |"), "{section}");
    // each model's rungs, then its paper row: HCP's block before RCP's
    let order: Vec<&str> = section
        .lines()
        .filter(|l| l.starts_with("| hcp_") || l.starts_with("| rcp_") || l.starts_with("| paper ("))
        .map(|l| l.split(" | ").next().unwrap())
        .collect();
    assert_eq!(
        order,
        [
            "| hcp_full",
            "| paper (HCP)",
            "| rcp_small",
            "| rcp_big",
            "| paper (RCP)"
        ],
        "{section}"
    );
    assert!(section.contains("| paper (HCP) | 42 062 |"), "{section}");
    assert!(
        section.contains("| hcp_full | 120 |") && section.contains("| 2.60 h, 50.0° |"),
        "{section}"
    );
    assert!(md.contains("--ladder "), "the command line names --ladder");
    for (figure, paper) in [
        ("ladder", ["HCP paper (Table 3): 2.4", "RCP paper (Table 3): 2.83"]),
        ("ladder_phi", ["HCP paper (Table 3): 43", "RCP paper (Table 3): 30"]),
        (
            "ladder_limits",
            ["HCP paper (Table 3): 2.38", "RCP paper (Table 3): 2.51"],
        ),
    ] {
        let svg = std::fs::read_to_string(out.join(format!("{figure}.svg"))).expect(figure);
        for line in paper {
            assert!(svg.contains(line), "{figure}.svg lacks the paper's line {line}");
        }
        assert!(section.contains(&format!("({figure}.png)")), "{figure} in the section");
    }
    let _ = std::fs::remove_dir_all(&root);
}

/// Writes a search's `critical.csv`: one hold per `(T_final, released, ours stable, paper stable)`.
fn critical_csv(dir: &Path, holds: &[(f64, bool, bool, bool)]) {
    std::fs::create_dir_all(dir).unwrap();
    let mut csv = "t_final_h,released,theta_max_deg,drift_theta_max_deg,drift_packing,drift_coordination,\
                   paper_stable,paper_drifting,ours_stable,ours_drifting\n"
        .to_string();
    for &(t, released, ours, paper) in holds {
        let theta = 100.0 - 20.0 * t;
        csv += &format!(
            "{t:.2},{released},{theta:.3},0.1,-0.00001,-0.09,{paper},{},{ours},{}\n",
            if paper { "" } else { "coordination_number" },
            if ours { "" } else { "theta_max" }
        );
    }
    std::fs::write(dir.join("critical.csv"), csv).unwrap();
}

/// `--ordering`: the variants' T_c,3 of HCP and RCP side by side with RCP − HCP (positive: the paper's order), a
/// search without a stable hold as "> its slowest hold", the nominal row from RUNS, a variant's coarse and fine
/// searches judged as one; and the Fig. 22 analogue:
/// every search with a `holds.csv` gets its hold table (with the density a hold stands for at 2.26 h) and figure,
/// the φ of a search being the θ_max of its T_c,3 hold, not of the released hold beside it.
#[test]
fn ordering_and_holds_sections_read_the_variants_and_their_holds() {
    let root = std::env::temp_dir().join(format!("rp_report_ordering_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    fake_run(&root.join("runs/hcp"), 30, 38300.0, 38300.0, 600.0, true);
    fake_run(&root.join("runs/rcp"), 30, 38300.0, 38300.0, 600.0, true);
    critical_csv(
        &root.join("runs/hcp/critical"),
        &[
            (2.60, true, false, false),
            (2.64, false, true, false),
            (2.68, false, true, false),
        ],
    );
    critical_csv(
        &root.join("runs/rcp/critical"),
        &[
            (2.55, true, false, false),
            (2.60, false, true, true),
            (2.65, false, true, true),
        ],
    );
    // β = 0: RCP stops failing at 2.90 h (where it creeps), HCP at 2.70 h (the paper's order), though HCP's slowest
    // hold creeps
    critical_csv(
        &root.join("ordering/rcp_beta0"),
        &[
            (2.80, true, false, false),
            (2.90, false, false, false),
            (3.00, false, true, false),
        ],
    );
    // HCP's in two searches, judged together: the fine one's 2.70 h hold is where it stops failing
    critical_csv(
        &root.join("ordering/hcp_beta0/critical"),
        &[(2.66, true, false, false), (2.74, false, true, false)],
    );
    critical_csv(
        &root.join("ordering/hcp_beta0/critical_fine"),
        &[(2.70, false, true, false), (2.78, false, false, false)],
    );
    // the nominal RCP's holds, as compact.py writes them
    let mut holds = "t_final_h,t_hold_s,period_h,body_mass_fraction,packing_fraction,coordination_number,\
                     coordination_loaded,theta_max_deg\n"
        .to_string();
    for t in ["2.55", "2.60", "2.65"] {
        for k in 0..20 {
            holds += &format!("{t},{},{t},1.0,0.64,{},,50.0\n", 200 * k, 4.0 + 0.01 * k as f64);
        }
    }
    std::fs::write(root.join("runs/rcp/critical/holds.csv"), &holds).unwrap();
    let beta0_holds = holds
        .replace("2.65", "3.00")
        .replace("2.60", "2.90")
        .replace("2.55", "2.80");
    std::fs::write(root.join("ordering/rcp_beta0/holds.csv"), beta0_holds).unwrap();
    let out = root.join("out");
    let md = std::fs::read_to_string(
        write_report(
            &ReportSources {
                ordering: Some(&root.join("ordering")),
                ..ReportSources::new(&root.join("runs"))
            },
            &out,
            false,
        )
        .unwrap(),
    )
    .unwrap();
    let section = &md[md.find("## Packing ordering").expect("an ordering section")..];
    let row = |start: &str| line_starting(section, start);
    let nominal = row("| Zhang17 Eqs. 11–12");
    assert!(
        nominal.contains(
            "| 2.64 h, 47.2° | > 2.68 h | 2.64 h | R 2.60, S 2.64, S 2.68 \
             | 2.60 h, 48.0° | 2.60 h, 48.0° | 2.60 h | R 2.55, S 2.60, S 2.65 | -0.04 |"
        ),
        "{nominal}"
    );
    let beta0 = row("| β = 0");
    assert!(
        beta0.contains(
            "| > 2.78 h | > 2.78 h | 2.70 h | R 2.66, S 2.70, S 2.74, C 2.78 \
             | 3.00 h, 40.0° | > 3.00 h | 2.90 h | R 2.80, C 2.90, S 3.00 | +0.20 |"
        ),
        "{beta0}"
    );
    assert!(row("| paper (Table 3").ends_with("| +0.43 |"));
    assert!(!section.contains("caps × 2"), "variants not run get no row");
    // the holds: the figures come from the ladder's and the ordering's searches (not RUNS'), here the β = 0 one
    let holds_md = &md[md.find("## Holds").expect("a holds section")..];
    assert!(holds_md.contains("### contact law rcp_beta0"), "{holds_md}");
    assert!(holds_md.contains("| 3.00 | "), "{holds_md}");
    assert!(out.join("fig22_contact_law_rcp_beta0.png").is_file());
    let _ = std::fs::remove_dir_all(&root);
}

/// The first line of a report section that starts with `start` (a table row), or a panic showing the section.
fn line_starting(section: &str, start: &str) -> String {
    section
        .lines()
        .find(|l| l.starts_with(start))
        .unwrap_or_else(|| panic!("no row {start}: {section}"))
        .to_string()
}

/// A fresh scratch directory for one test.
fn fresh_root(tag: &str) -> std::path::PathBuf {
    let root = std::env::temp_dir().join(format!("rp_report_{tag}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    root
}

/// The report of `root/runs` alone (no optional sections), written to `root/out`.
fn report_of_runs(root: &Path) -> String {
    let path = write_report(&ReportSources::new(&root.join("runs")), &root.join("out"), false).unwrap();
    std::fs::read_to_string(path).unwrap()
}

/// Table 7 (Zhang17 §4.4): a material variant `<model>_beta<β>_mus<μ_s>` gets its own row beside the paper's (the
/// pile it was spun up from, T_c3 by both criteria, where it stops failing, φ, and κ₃ and the critical bulk density
/// of Eq. 22 from its one density), is not a Table 3 row, and is not taken for a second bulk density of its model;
/// Table 3 gives T_c3 by both criteria.
#[test]
fn material_section_sets_each_material_beside_table_7() {
    let root = fresh_root("materials");
    fake_run(&root.join("runs/hcp"), 30, 38300.0, 38300.0, 600.0, true);
    critical_csv(
        &root.join("runs/hcp/critical"),
        &[(2.60, true, false, false), (2.64, false, true, false)],
    );
    let weak = root.join("runs/hcp_beta0.3_mus0.5");
    fake_run(&weak, 30, 38300.0, 38300.0, 600.0, true);
    std::fs::write(
        weak.join("path2/scene.toml"),
        "[scene]\nt_end = 38300.0\nparticles_file = \"../../targets/zhang2017/hcp_settled_beta0.3_mus0.5.csv\"\n\n\
         [spinup]\nt_start = 700.0\n",
    )
    .unwrap();
    critical_csv(
        &weak.join("critical"),
        &[
            (2.50, true, false, false),
            (2.56, false, true, false),
            (2.62, false, true, true),
        ],
    );
    let md = report_of_runs(&root);
    let table3 = &md[..md.find("## T_c,3 by creep criterion").expect("criterion section")];
    let hcp = table3.lines().find(|l| l.starts_with("| HCP |")).expect("HCP row");
    assert!(
        hcp.contains("| – / 2.64 | – / 47.2 |"),
        "both criteria in Table 3: {hcp}"
    );
    assert!(
        !table3.contains("| HCP_BETA"),
        "a material is not a Table 3 row: {table3}"
    );
    assert!(!md.contains("### HCP"), "nor a second bulk density of HCP");
    let section = &md[md.find("## Material").expect("a Table 7 section")..];
    let row = |start: &str| line_starting(section, start);
    // Eq. 22 by hand for the weak material's T_c3 (ours) of 2.56 h at this fake body's bulk density
    let rho = 2100.0 * 30.0 * 1e7 / rubblepile::analysis::spinup::DIDYMOS_MASS;
    let omega = 2.0 * std::f64::consts::PI / (2.56 * 3600.0);
    let kappa = omega / (4.0 * std::f64::consts::PI * 6.674e-11 * rho / 3.0).sqrt();
    let rho_c = rho * (2.56f64 / 2.26).powi(2);
    assert_eq!(
        row("| HCP | 0.3, 0.5 |"),
        format!(
            "| HCP | 0.3, 0.5 | `hcp_settled_beta0.3_mus0.5.csv` | – / – | 2.62 / 2.56 | 2.56 | 48.8 | \
             {kappa:.3}, {rho_c:.0} | 0.937, 2430, 42° |"
        )
    );
    assert!(
        row("| HCP | 0.5, 1.0 |").contains("| 2.64 | 47.2 |"),
        "the nominal row is Table 3's"
    );
    assert!(row("| HCP | 0.6, 1.3 |").contains("| not run |"));
    assert!(
        !section.contains("| PP2 |"),
        "a model without a Table 3 run gets no rows"
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// The Runs table gives, beside the run's largest overlap, the largest sampled one up to the failure (the sample of
/// the later of T_c,1 and T_c,2): the part of the run that sets them, without the failure's collisions.
#[test]
fn overlap_before_failure_leaves_out_the_collisions_after_it() {
    let root = fresh_root("overlap");
    let model = root.join("runs/hcp");
    // b/a drops once the period is below 4 h: the sample at t = 19 200 s gives T_c,1, and no T_c,2
    fake_run_at(&model, "path2", 30, 38300.0, 38300.0, 600.0, true, Some(4.0));
    let ts = model.join("path2/timeseries.csv");
    let text = std::fs::read_to_string(&ts).unwrap();
    let mut out = String::new();
    for (k, line) in text.lines().enumerate() {
        let mut cells: Vec<String> = line.split(',').map(String::from).collect();
        if k > 0 {
            let t: f64 = cells[0].parse().unwrap();
            cells[4] = if t <= 19200.0 { "0.005" } else { "0.03" }.into();
        }
        out += &cells.join(",");
        out.push('\n');
    }
    std::fs::write(&ts, out).unwrap();
    let md = report_of_runs(&root);
    let runs = &md[md.find("## Runs").expect("runs table")..];
    let row = runs.lines().find(|l| l.starts_with("| HCP |")).expect("HCP row");
    assert!(row.contains("| 4.00e-3, 5.00e-3 |"), "{row}");
    let _ = std::fs::remove_dir_all(&root);
}

/// The Fig. 22 analogue shows the paper's own model, PP2, at every bulk density run under RUNS (Table 3's run and
/// the Eq. 22 variants), each hold with the density it stands for at 2.26 h; other models' Table 3 searches are
/// not shown there.
#[test]
fn holds_section_shows_pp2_at_each_density_run() {
    let root = fresh_root("pp2_holds");
    for m in ["pp2", "pp2_rho2400", "hcp"] {
        fake_run(&root.join("runs").join(m), 30, 38300.0, 38300.0, 600.0, true);
        let search = root.join("runs").join(m).join("critical");
        critical_csv(&search, &[(2.50, true, false, false), (2.60, false, true, true)]);
        let mut holds = "t_final_h,t_hold_s,period_h,body_mass_fraction,packing_fraction,coordination_number,\
                         coordination_loaded,theta_max_deg\n"
            .to_string();
        for t in ["2.50", "2.60"] {
            for k in 0..10 {
                holds += &format!("{t},{},{t},1.0,0.69,{},,40.0\n", 400 * k, 5.0 + 0.01 * k as f64);
            }
        }
        std::fs::write(search.join("holds.csv"), holds).unwrap();
    }
    let md = report_of_runs(&root);
    let holds_md = &md[md.find("## Holds").expect("a holds section")..];
    assert!(holds_md.contains("### runs pp2 critical"), "{holds_md}");
    assert!(holds_md.contains("### runs pp2_rho2400 critical"), "{holds_md}");
    assert!(!holds_md.contains("### runs hcp"), "{holds_md}");
    let _ = std::fs::remove_dir_all(&root);
}

/// A user's run directory (`rubblepile run` of a spin-up scene: `spinup.csv` directly in it, a name not in Table 3)
/// is read beside this project's `<model>/path2` layout, gets its row with "–" in the paper's column, and the
/// report says which layout it read; RUNS may also be that run directory itself.
#[test]
fn a_users_run_directory_gets_its_row() {
    let root = fresh_root("user_layout");
    fake_run(&root.join("runs/hcp"), 30, 38300.0, 38300.0, 600.0, true);
    fake_run_at(
        &root.join("runs"),
        "myrun",
        40,
        38300.0,
        38300.0,
        600.0,
        true,
        Some(2.6),
    );
    let md = report_of_runs(&root);
    let row = line_starting(&md, "| MYRUN |");
    assert!(row.contains("| 40 |"), "N: {row}");
    assert!(row.ends_with("| – |"), "the paper's column: {row}");
    assert!(line_starting(&md, "| HCP |").contains("2.38/2.36/2.40 h"));
    assert!(
        md.contains("`<model>/path2/spinup.csv` for 1 models"),
        "{}",
        &md[..1200]
    );
    assert!(
        md.contains("`spinup.csv` directly in them for myrun"),
        "{}",
        &md[..1200]
    );
    assert!(md.contains("– in its columns: myrun."), "{}", &md[..1200]);
    // RUNS is the run directory itself
    let one = root.join("runs/myrun");
    let path = write_report(&ReportSources::new(&one), &root.join("out_one"), false).unwrap();
    let md = std::fs::read_to_string(path).unwrap();
    assert!(line_starting(&md, "| MYRUN |").contains("| 40 |"));
    assert!(md.contains("is one run directory"), "{}", &md[..1200]);
    // a directory with no spin-up run is refused with a message naming the layouts
    let err = write_report(&ReportSources::new(&root.join("out")), &root.join("out_none"), false).unwrap_err();
    assert!(err.to_string().contains("<run>/spinup.csv"), "{err}");
    let _ = std::fs::remove_dir_all(&root);
}

/// The body's size and bulk density in the text are the runs', not the paper's D = 780 m: for the fake runs' n
/// grains of 10 m radius and 1e7 kg at η_B = 0.74, V = n (4/3)π 10³ / 0.74, so D = 20 (n/0.74)^(1/3) m and
/// ρ_B = 0.74 × 1e7 / ((4/3)π 10³) kg/m³; and the aggregate's record beside the scene's particles file, when it
/// is of the run's mass, gives its own values instead.
#[test]
fn the_body_in_the_text_is_the_runs() {
    let root = fresh_root("body");
    fake_run(&root.join("runs/hcp"), 30, 38300.0, 38300.0, 600.0, true);
    let md = report_of_runs(&root);
    let d = 20.0 * (30.0f64 / 0.74).cbrt();
    let rho = 0.74 * 1e7 / (4.0 / 3.0 * std::f64::consts::PI * 1e3);
    let expected = format!("ours keep the body (D ≈ {d:.0} m, ρ_B ≈ {rho:.0} kg/m³ (the grains' volume over η_B");
    assert!(md.contains(&expected), "{expected}: {md}");
    assert!(!md.contains("D = 780 m"));
    // with the aggregate's record of a 1234 m body of the run's mass (30 × 1e7 kg)
    let run = root.join("runs/hcp/path2");
    let scene = std::fs::read_to_string(run.join("scene.toml")).unwrap();
    let scene = scene.replace("[scene]\n", "[scene]\nparticles_file = \"agg.csv\"\n");
    std::fs::write(run.join("scene.toml"), scene).unwrap();
    std::fs::write(
        run.join("agg.json"),
        r#"{"total_mass_kg": 3e8, "shape_equivalent_diameter_m": 1234.0, "bulk_density_kg_m3": 1500.0}"#,
    )
    .unwrap();
    let path = write_report(&ReportSources::new(&root.join("runs")), &root.join("out"), true).unwrap();
    let md = std::fs::read_to_string(path).unwrap();
    assert!(
        md.contains("ours keep the body (D = 1234 m, ρ_B = 1500 kg/m³ (the aggregate's record))"),
        "{md}"
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// A shape that departs at the second forced sample (200 s after t_start's, within the dynamical time
/// 1/√(Gρ_B) ≈ 2900 s of the fake body) marks T_c1 as read in the settling, in its cell and in a warning line;
/// one that departs 18 000 s later is quoted plainly.
#[test]
fn a_departure_at_t_start_is_flagged_as_settling() {
    let root = fresh_root("settling");
    // period 5 − 2t/38300 h: below 4.95 h from t = 957 s, the sample at 1000 s (the first forced one is at 800 s)
    fake_run_at(
        &root.join("runs/hcp"),
        "path2",
        30,
        38300.0,
        38300.0,
        600.0,
        true,
        Some(4.95),
    );
    let md = report_of_runs(&root);
    let row = line_starting(&md, "| HCP |");
    assert!(row.contains("| 4.948 ⚠ settling |"), "{row}");
    assert!(
        md.contains("**Warning** (settling, Zhang17 §2.3.4): HCP: T_c1 is read 200 s after t_start"),
        "{md}"
    );
    // below 4.0 h from t = 19 150 s: outside the settling
    let root = fresh_root("settled");
    fake_run_at(
        &root.join("runs/hcp"),
        "path2",
        30,
        38300.0,
        38300.0,
        600.0,
        true,
        Some(4.0),
    );
    let md = report_of_runs(&root);
    let row = line_starting(&md, "| HCP |");
    assert!(row.contains("| 3.997 |"), "{row}");
    assert!(!md.contains("⚠ settling") && !md.contains("**Warning**"), "{md}");
    let _ = std::fs::remove_dir_all(&root);
    let _ = std::fs::remove_dir_all(fresh_root("settling"));
}

/// Table 3's T_c3 column shows the paper's criterion read with tolerances (the rule of the committed searches) and
/// says so: on a search where `spinup critical`'s default (zero tolerance) gives 2.70 h and the tolerance rule 2.60
/// h, the column is labelled `paper-tolerance` and holds 2.60 h, and no column calls it "paper's". The header names
/// `--force` only when it was given.
#[test]
fn table3_labels_the_tolerance_rule_it_shows_and_the_header_the_flags_given() {
    let root = fresh_root("tolerance_label");
    fake_run(&root.join("runs/rcp"), 30, 38300.0, 38300.0, 600.0, true);
    let crit = root.join("runs/rcp/critical");
    std::fs::create_dir_all(&crit).unwrap();
    std::fs::write(
        crit.join("critical.json"),
        r#"{"t_c3_hours": 2.70, "friction_angle_deg": 37.9, "runs": [],
            "paper": {"t_c3_hours": 2.70, "friction_angle_deg": 37.9},
            "paper_tolerance": {"t_c3_hours": 2.60, "friction_angle_deg": 45.9},
            "ours": {"t_c3_hours": 2.60, "friction_angle_deg": 45.9}}"#,
    )
    .unwrap();
    let md = report_of_runs(&root);
    let header = md.lines().find(|l| l.starts_with("| model | N |")).expect("Table 3");
    assert!(
        header.contains("| T_c3 (h), paper-tolerance / ours | φ (°), paper-tolerance / ours |"),
        "{header}"
    );
    assert!(
        !md.contains("paper's / ours"),
        "a column still calls the tolerance rule the paper's"
    );
    let row = md.lines().find(|l| l.starts_with("| RCP |")).expect("RCP row");
    assert!(row.contains("| 2.60 / 2.60 | 45.9 / 45.9 |"), "{row}");
    assert!(md.contains("the paper's criterion with zero tolerance, `spinup critical`'s default"));
    let generated = md.lines().find(|l| l.starts_with("Generated by")).unwrap();
    assert!(!generated.contains("--force"), "{generated}");
    let again = write_report(&ReportSources::new(&root.join("runs")), &root.join("out"), true).unwrap();
    let md = std::fs::read_to_string(again).unwrap();
    assert!(
        md.lines()
            .any(|l| l.starts_with("Generated by") && l.contains(" --force` from"))
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// A `spinup critical` directory given as RUNS (its holds `T<period>/` and `base/` would be read as models) is
/// refused in one line that names the layout expected and how to lay it out.
#[test]
fn a_search_directory_given_as_runs_is_refused_with_the_layout() {
    let root = fresh_root("search_as_runs");
    let search = root.join("t6_crit");
    fake_run_at(&search, "base", 30, 38300.0, 38300.0, 600.0, true, None);
    fake_run_at(&search, "T2.50", 30, 38300.0, 38300.0, 600.0, false, None);
    for with_json in [false, true] {
        if with_json {
            std::fs::write(search.join("critical.json"), "{}").unwrap();
        }
        let e = write_report(&ReportSources::new(&search), &root.join("out"), false)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("search directory")
                && e.contains("RUNS/<model>/path2/")
                && e.contains("RUNS/<model>/critical/")
                && e.contains("t6_crit/base")
                && !e.contains('\n'),
            "{e}"
        );
        assert!(!root.join("out/REPORT.md").exists());
    }
    let _ = std::fs::remove_dir_all(&root);
}
