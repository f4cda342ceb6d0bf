//! The same scene gives the same output bits on 1, 2, 3 and 4 threads, for every engine, through the binary as a
//! user runs it (`RAYON_NUM_THREADS`): the N200 impact across first contact (every parallel pass of the ellipsoid
//! right-hand side, the per-body pair sums, the gravity blocks), a 1261-sphere soft-sphere ball under tree
//! self-gravity, and the hard-sphere box. Only the columns that measure the machine may differ.

mod common;
use common::temp_dir;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run_on(threads: usize, cwd: &Path, args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_rubblepile"))
        .args(args)
        .env("RAYON_NUM_THREADS", threads.to_string())
        .current_dir(cwd)
        .output()
        .expect("run the binary");
    assert!(
        out.status.success(),
        "{threads} threads: {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Every output file of a run directory except the machine's (summary wall times, lock files), with the
/// `wall_seconds` column of CSV files dropped, as (relative path, text).
fn outputs(dir: &Path) -> Vec<(String, String)> {
    fn walk(base: &Path, dir: &Path, out: &mut Vec<(String, String)>) {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()).collect();
        entries.sort();
        for p in entries {
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            if p.is_dir() {
                walk(base, &p, out);
            } else if !name.starts_with('.') && name != "summary.json" && name != "manifest.txt" {
                // (the manifest's checksums cover the wall-clock column of the time series, which differs)
                let text = std::fs::read_to_string(&p).unwrap_or_default();
                let rel = p.strip_prefix(base).unwrap().display().to_string();
                out.push((rel, without_wall(&text)));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out
}

fn without_wall(text: &str) -> String {
    let mut lines = text.lines();
    let Some(header) = lines.next() else {
        return String::new();
    };
    // Columns that measure the machine: wall time, and the hard-sphere engine's events per wall second.
    let machine: Vec<usize> = header
        .split(',')
        .enumerate()
        .filter(|(_, c)| ["wall_seconds", "events_per_second"].contains(c))
        .map(|(k, _)| k)
        .collect();
    if machine.is_empty() {
        return text.to_string();
    }
    std::iter::once(header)
        .chain(lines)
        .map(|l| {
            let cells: Vec<&str> = l
                .split(',')
                .enumerate()
                .filter(|(k, _)| !machine.contains(k))
                .map(|(_, c)| c)
                .collect();
            cells.join(",") + "\n"
        })
        .collect()
}

fn same_on_one_to_four_threads(tag: &str, args: impl Fn(&str) -> Vec<String>, cwd: &Path) {
    let reference_dir = format!("{tag}_1");
    let a = args(&reference_dir);
    run_on(1, cwd, &a.iter().map(String::as_str).collect::<Vec<_>>());
    let reference = outputs(&cwd.join(&reference_dir));
    assert!(
        reference.iter().any(|(p, _)| p.starts_with("snapshots")),
        "{tag}: no snapshots"
    );
    for threads in [2, 3, 4] {
        let dir = format!("{tag}_{threads}");
        let a = args(&dir);
        run_on(threads, cwd, &a.iter().map(String::as_str).collect::<Vec<_>>());
        let got = outputs(&cwd.join(&dir));
        assert_eq!(got.len(), reference.len(), "{tag}: files on {threads} threads");
        for ((p, text), (_, want)) in got.iter().zip(&reference) {
            assert!(text == want, "{tag}: {p} differs between 1 and {threads} threads");
        }
    }
}

#[test]
fn ellipsoid_impact_is_bit_identical_on_one_to_four_threads() {
    let dir = temp_dir("threads-ellipsoids");
    let target = root().join("targets/N200_T4.csv").display().to_string();
    same_on_one_to_four_threads(
        "impact",
        |out| {
            [
                "impact",
                "--target",
                &target,
                "--projectile",
                "P2",
                "--t-end-s",
                "110",
                "--out",
                out,
                "--no-progress",
            ]
            .iter()
            .map(|s| s.to_string())
            .collect()
        },
        &dir,
    );
}

#[test]
fn soft_sphere_ball_is_bit_identical_on_one_to_four_threads() {
    let dir = temp_dir("threads-soft");
    let scene = format!(
        "[scene]\nkind = \"soft-spheres\"\nt_end = 2e-4\nseed = 1\nparticles_file = {:?}\n\
         [stepping]\ndt = 4e-6\n[material]\nk_n = 1.5e11\neps_n = 0.1\neps_t = 0.1\n\
         [gravity]\nself = \"tree\"\ntheta = 0.5\nG = 1.0\n[output]\nevery = 4e-5\ntimes = [0.0, 2e-4]\n",
        root().join("tests/data/settled_hcp_ball.csv").display().to_string()
    );
    std::fs::write(dir.join("ball.toml"), scene).unwrap();
    same_on_one_to_four_threads(
        "soft",
        |out| {
            ["run", "ball.toml", "--out", out, "--no-progress"]
                .iter()
                .map(|s| s.to_string())
                .collect()
        },
        &dir,
    );
}

#[test]
fn hard_sphere_box_is_bit_identical_on_one_to_four_threads() {
    let dir = temp_dir("threads-hard");
    let scene = root().join("tests/golden/hard_box/scene.toml").display().to_string();
    same_on_one_to_four_threads(
        "hard",
        |out| {
            ["run", &scene, "--out", out, "--no-progress"]
                .iter()
                .map(|s| s.to_string())
                .collect()
        },
        &dir,
    );
}
