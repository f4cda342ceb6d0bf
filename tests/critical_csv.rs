//! A T_c,3 search's `critical.csv` read back (`critical::read_critical_csv`), so that the Zhang17 tables
//! regenerate from committed compact copies: every committed CSV of today's layout round-trips byte for byte, one
//! of the layout before Dec 2026 keeps its verdicts through a rewrite, the T_c,3 and φ re-derived from it equal
//! those its search wrote into `critical.json`, and a malformed row names its column.

use rubblepile::analysis::creep::CreepCriterionKind;
use rubblepile::analysis::critical::{
    CRITICAL_CSV_HEADER, CRITICAL_CSV_HEADER_V1, critical_csv, read_critical, read_critical_csv,
};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The committed files written by `spinup critical` (its header; `critical/pp1_path2_critical.csv` is a table
/// written by hand from a search stopped early, in another layout).
fn committed_csvs() -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![root().join("analysis/zhang2017")];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "csv")
                && [CRITICAL_CSV_HEADER, CRITICAL_CSV_HEADER_V1]
                    .iter()
                    .any(|h| std::fs::read_to_string(&p).unwrap().starts_with(h))
            {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

#[test]
fn committed_critical_csvs_round_trip() {
    let files = committed_csvs();
    assert!(files.len() >= 8, "{files:?}");
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let holds = read_critical_csv(&text).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        assert!(!holds.is_empty(), "{}", f.display());
        if text.starts_with(CRITICAL_CSV_HEADER) {
            assert_eq!(critical_csv(&holds), text, "{}", f.display());
            continue;
        }
        // the old layout: its verdicts survive a rewrite in today's, where they are the paper-tolerance ones
        let again = read_critical_csv(&critical_csv(&holds)).unwrap();
        for (a, b) in holds.iter().zip(&again) {
            assert_eq!(a.released, b.released, "{}", f.display());
            for k in CreepCriterionKind::ALL {
                assert_eq!(a.verdict(k), b.verdict(k), "{} {k:?}", f.display());
            }
            assert!(a.verdict(CreepCriterionKind::Paper).is_none(), "{}", f.display());
        }
    }
}

/// The searches committed with both files: T_c,3 and φ by both criteria from the CSV alone equal the JSON's.
#[test]
fn t_c3_from_the_csv_equals_the_searchs_own() {
    let searches = [
        "analysis/zhang2017/ladder/rcp_2k/critical",
        "analysis/zhang2017/ladder/rcp_8k/critical",
        "analysis/zhang2017/ladder/rcp_8k/critical_fine",
    ];
    let tmp = std::env::temp_dir().join(format!("rp_critical_csv_{}", std::process::id()));
    for s in searches {
        let dir = root().join(s);
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("critical.json")).unwrap()).unwrap();
        let whole = read_critical(&dir).unwrap();
        let only_csv = tmp.join(Path::new(s).file_name().unwrap());
        std::fs::create_dir_all(&only_csv).unwrap();
        std::fs::copy(dir.join("critical.csv"), only_csv.join("critical.csv")).unwrap();
        let derived = read_critical(&only_csv).unwrap();
        // these searches predate the rates: their JSON's `paper` is today's paper-tolerance criterion
        for (new, old) in [("paper_tolerance", "paper"), ("ours", "ours")] {
            assert_eq!(derived[new]["t_c3_hours"], json[old]["t_c3_hours"], "{s} {new}");
            // φ by today's rule (the T_c3 hold's θ_max since 28 Nov 2026), with or without the holds' records
            match (
                derived[new]["friction_angle_deg"].as_f64(),
                whole[new]["friction_angle_deg"].as_f64(),
            ) {
                (Some(a), Some(b)) => assert!((a - b).abs() < 1e-3, "{s} {new}: {a} vs {b}"),
                (a, b) => assert_eq!(a, b, "{s} {new}"),
            }
        }
        assert_eq!(
            derived["runs"].as_array().unwrap().len(),
            json["runs"].as_array().unwrap().len()
        );
        std::fs::remove_dir_all(&only_csv).unwrap();
    }
}

#[test]
fn a_malformed_row_names_its_line_and_column() {
    let header = "t_final_h,released,theta_max_deg,drift_theta_max_deg,drift_packing,drift_coordination,paper_stable,paper_drifting,ours_stable,ours_drifting\n";
    let bad_number = format!("{header}2.50,true,abc,0,0,0,false,,false,\n");
    let e = read_critical_csv(&bad_number).unwrap_err();
    assert!(e.contains("line 2") && e.contains("theta_max_deg"), "{e}");
    let bad_name = format!("{header}2.50,true,50,0,0,0,false,spin,false,\n");
    let e = read_critical_csv(&bad_name).unwrap_err();
    assert!(e.contains("paper_drifting") && e.contains("spin"), "{e}");
    assert!(read_critical_csv("t,x\n").unwrap_err().contains("header"));
}
