//! Issue 57: units on the command line. Every flag of every subcommand either names its unit as a suffix or is in
//! the allow-list of dimensionless flags; the old spellings (`src/cli/units.rs`) still parse with one warning line;
//! the README's commands use no old spelling.

use std::path::Path;
use std::process::{Command, Output};

/// The unit suffixes of the rule (README, "Units on the command line").
const SUFFIXES: &[&str] = &[
    "-s", "-h", "-m", "-km", "-m-s", "-km-s", "-deg", "-kg", "-kg-m3", "-rad-s",
];

/// Flags whose value carries no unit: counts, fractions, κ, β, tolerances, seeds, names, files, switches; `--f0`
/// (the paper's symbol F0, s m⁻², in its help), `--size` (pixels), `--time`/`--mem` (passed to sbatch as written),
/// `--hsdem-from`/`--hsdem-window` and `--rk4-steps` (in the problem's own dimensionless units), `--start-q` (in q).
const DIMENSIONLESS: &[&str] = &[
    "account",
    "all-holds",
    "atmosphere",
    "baseline",
    "beta",
    "binary",
    "bodies",
    "bootstrap-seed",
    "branch",
    "by",
    "campaign-runs",
    "candidate",
    "cases",
    "color",
    "compact",
    "coordination-tolerance",
    "creep-criterion",
    "csv",
    "decided",
    "drop-detached",
    "dump-particles",
    "explain",
    "f0",
    "finish-released",
    "force",
    "format",
    "fragments",
    "full",
    "gif",
    "gravity",
    "gravity-interval",
    "half",
    "help",
    "hsdem-from",
    "hsdem-window",
    "impact-parameter-frac",
    "inertia",
    "input",
    "kappa",
    "kappa-reading",
    "keep-runs",
    "ladder",
    "lattice-orientation",
    "max-overlap",
    "max-steps",
    "mem",
    "method",
    "methods",
    "migrate",
    "model",
    "no-control",
    "no-phases",
    "no-progress",
    "no-run",
    "obj-scale",
    "only",
    "ordering",
    "other-kappa",
    "out",
    "parallel",
    "particles",
    "partition",
    "paths",
    "phases",
    "pile-fixed-attitude",
    "planet-j2",
    "planet-pole",
    "points",
    "prepare-only",
    "print-default",
    "problem",
    "problems",
    "projectile",
    "projectile-attitude",
    "projectile-pile",
    "quick",
    "reference-rtol",
    "render",
    "repeat",
    "repeats",
    "replot",
    "report",
    "resume",
    "reuse-prepared",
    "rigidity",
    "rk4-steps",
    "root",
    "rtol",
    "scene",
    "seed",
    "settle-to-principal",
    "shake-periods",
    "shape",
    "shard",
    "significance",
    "single-thread",
    "size",
    "snapshots",
    "spheres",
    "spin-target",
    "ssdem-steps",
    "start-q",
    "steps",
    "target",
    "targets",
    "tasks",
    "theta",
    "threads",
    "threads-per-hold",
    "threads-per-rank",
    "threads-per-task",
    "throttle",
    "time",
    "to",
    "tumbler",
    "uniform",
    "version",
    "view",
];

fn rubblepile(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rubblepile"))
        .args(args)
        .output()
        .expect("run rubblepile")
}

/// Subcommand names and long flags of `rubblepile PATH --help`.
fn help_of(path: &[String]) -> (Vec<String>, Vec<String>) {
    let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
    args.push("--help");
    let out = rubblepile(&args);
    assert!(out.status.success(), "rubblepile {args:?} failed");
    let text = String::from_utf8(out.stdout).unwrap();
    let (mut commands, mut flags) = (Vec::new(), Vec::new());
    let mut section = "";
    for line in text.lines() {
        if !line.starts_with(' ') {
            section = line.trim_end_matches(':');
            continue;
        }
        let t = line.trim_start();
        let indent = line.len() - t.len();
        if section == "Commands" && indent == 2 {
            let name = t.split_whitespace().next().unwrap();
            if name != "help" {
                commands.push(name.to_string());
            }
        }
        if section == "Options" && indent <= 6 {
            let t = t.split_once(", ").filter(|(s, _)| s.len() == 2).map_or(t, |(_, l)| l);
            if let Some(l) = t.strip_prefix("--") {
                flags.push(l.split([' ', '=']).next().unwrap().to_string());
            }
        }
    }
    (commands, flags)
}

#[test]
fn every_flag_names_its_unit_or_is_dimensionless() {
    let mut todo = vec![Vec::<String>::new()];
    let (mut bad, mut seen) = (Vec::new(), Vec::new());
    while let Some(path) = todo.pop() {
        let (commands, flags) = help_of(&path);
        for c in commands {
            todo.push(path.iter().cloned().chain([c]).collect());
        }
        for f in flags {
            if !DIMENSIONLESS.contains(&f.as_str()) && !SUFFIXES.iter().any(|s| f.ends_with(s)) {
                bad.push(format!("rubblepile {} --{f}", path.join(" ")));
            }
            seen.push(f);
        }
    }
    assert!(seen.len() > 250, "only {} flags found: is the help parsed?", seen.len());
    for f in [
        "t-end-s",
        "angle-deg",
        "q-m",
        "hold-s",
        "bulk-density-kg-m3",
        "checkpoint-every-sim-s",
        "kappa",
    ] {
        assert!(seen.iter().any(|s| s == f), "--{f} not found in any help");
    }
    assert!(
        bad.is_empty(),
        "flags without a unit suffix (add one of {SUFFIXES:?}, or list a dimensionless flag in DIMENSIONLESS): {bad:?}"
    );
}

/// (scope, old, new, unit) of `src/cli/units.rs`'s `RENAMED`.
fn renamed() -> Vec<[String; 4]> {
    let src = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("src/cli/units.rs")).unwrap();
    let rows: Vec<[String; 4]> = src
        .lines()
        .filter_map(|l| l.trim().strip_prefix("(\"")?.strip_suffix("\"),").map(str::to_string))
        .map(|l| {
            let f: Vec<String> = l.split("\", \"").map(str::to_string).collect();
            [f[0].clone(), f[1].clone(), f[2].clone(), f[3].clone()]
        })
        .collect();
    assert!(rows.len() > 50, "RENAMED not read from src/cli/units.rs");
    rows
}

fn warnings(out: &Output) -> Vec<String> {
    String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter(|l| l.starts_with("warning:"))
        .map(str::to_string)
        .collect()
}

#[test]
fn an_old_flag_still_works_with_one_warning_line() {
    let points = "1800:3.1,2100:2.6,2400:2.3";
    let new = rubblepile(&["spinup", "density-fit", "--points", points, "--period-h", "2.5"]);
    let old = rubblepile(&["spinup", "density-fit", "--points", points, "--period", "2.5"]);
    let old_eq = rubblepile(&["spinup", "density-fit", "--points", points, "--period=2.5"]);
    assert!(new.status.success(), "{}", String::from_utf8_lossy(&new.stderr));
    assert!(warnings(&new).is_empty());
    for o in [&old, &old_eq] {
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert_eq!(o.stdout, new.stdout, "the old flag gives another result");
        assert_eq!(
            warnings(o),
            ["warning: --period is deprecated: use --period-h (same unit, h)"]
        );
    }
    // Given twice, one warning (clap then refuses the repeated flag).
    let twice = rubblepile(&["analyze", "no-such-dir", "--at", "5", "--at=6"]);
    assert_eq!(
        warnings(&twice),
        ["warning: --at is deprecated: use --at-s (same unit, s)"]
    );
    // Scoped per subcommand: `convert --to` is a file name, not `spinup critical --to` (hours).
    let convert = rubblepile(&["convert", "no-such-file.csv", "--to", "o.ss"]);
    assert!(warnings(&convert).is_empty(), "{:?}", warnings(&convert));
    // Nothing after a bare `--` is rewritten.
    let bench = rubblepile(&["bench", "impact", "--replot", "--out", "no-such-dir", "--", "--angle"]);
    assert!(warnings(&bench).is_empty(), "{:?}", warnings(&bench));
}

/// Whether `words` (the subcommand words after `rubblepile`) fall under `scope` ("" for every command).
fn applies(scope: &str, words: &[&str]) -> bool {
    scope
        .split_whitespace()
        .enumerate()
        .all(|(i, w)| words.get(i) == Some(&w))
}

#[test]
fn the_readme_uses_no_deprecated_flag() {
    let readme = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    let table = renamed();
    // Commands: fenced code blocks (continuation lines joined) and inline `rubblepile …` spans.
    let mut commands = Vec::new();
    for (i, block) in readme.split("```").enumerate() {
        if i % 2 == 1 {
            commands.extend(block.replace("\\\n", " ").lines().map(str::to_string));
        } else {
            commands.extend(block.split('`').skip(1).step_by(2).map(str::to_string));
        }
    }
    let mut bad = Vec::new();
    for c in commands
        .iter()
        .filter(|c| c.contains("rubblepile ") || c.contains("cargo run"))
    {
        let tail = c
            .rsplit("rubblepile ")
            .next()
            .unwrap_or(c)
            .rsplit("-- ")
            .next()
            .unwrap();
        let tokens: Vec<&str> = tail.split_whitespace().collect();
        let words: Vec<&str> = tokens.iter().copied().take_while(|t| !t.starts_with('-')).collect();
        for [scope, old, new, _] in &table {
            let flag = format!("--{old}");
            if applies(scope, &words) && tokens.iter().any(|t| *t == flag || t.starts_with(&format!("{flag}="))) {
                bad.push(format!("{c}: --{old} (now --{new})"));
            }
        }
    }
    assert!(bad.is_empty(), "the README uses deprecated flags: {bad:#?}");
}

/// Guards the joining of a negative value to its flag: `--angle-deg -5` reaches the flag's own range check (which
/// names the flag and the range) instead of clap's "unexpected argument '-5'".
#[test]
fn a_negative_value_after_a_space_reaches_the_flags_own_check() {
    let target = "targets/N30_T4.csv";
    let spaced = rubblepile(&[
        "impact",
        "--target",
        target,
        "--angle-deg",
        "-5",
        "--out",
        "/nonexistent/never-written",
    ]);
    let joined = rubblepile(&[
        "impact",
        "--target",
        target,
        "--angle-deg=-5",
        "--out",
        "/nonexistent/never-written",
    ]);
    let (spaced_err, joined_err) = (
        String::from_utf8_lossy(&spaced.stderr).to_string(),
        String::from_utf8_lossy(&joined.stderr).to_string(),
    );
    assert!(!spaced.status.success(), "{spaced_err}");
    assert!(!spaced_err.contains("unexpected argument"), "{spaced_err}");
    assert_eq!(spaced_err, joined_err);
    assert!(
        spaced_err.contains("--angle-deg: expected 0 to 180 degrees, got -5"),
        "{spaced_err}"
    );
}
