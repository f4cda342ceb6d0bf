//! The one vocabulary of the granular scene files (`rubblepile::granular::vocabulary`): the old names still read,
//! each with one warning naming the old key and the new one (by `check` and by `run`); `check --migrate` writes a
//! text that reads with no warning as the very same scene, to stdout, to `--out` or in place, never over a file
//! without `--force`; and every granular scene of the repository uses the current names.

mod common;

use std::path::{Path, PathBuf};

use common::{rubblepile, temp_dir};
use rubblepile::granular::{hard, migrate, soft};

/// The soft-sphere example as it was written before the names were unified.
const OLD_SOFT: &str = r#"[scene]
kind = "soft-spheres"
t_end = 10.0
seed = 1

[integrator]
dt = 7e-5                    # s

[contact]                    # Zhang17 Eqs. 1–12
k_n = 4.2e8                  # N/m
max_start_overlap = 0.05

[gravity]
uniform = [0.0, 0.0, -9.81]  # m/s²
self = "tree"

[output]
every = 0.1
times = [0.0, 10.0]

[[wall]]
kind = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
oscillation = { amplitude = [0.0, 0.0, 0.01], frequency = 5.0 }   # m, Hz

[[wall]]
kind = "sphere"
centre = [0.0, 0.0, 0.0]
radius = 5.0
[wall.oscillation]
amplitude = [-0.02, 0.0, 0.0]
frequency = 0.3

[[particle]]
radius = 0.5
density = 2000.0
position = [0.0, 0.0, 0.6]
velocity = [1.0, 0.0, 0.0]
"#;

/// The hard-sphere example as it was written before the names were unified, with a drum.
const OLD_HARD: &str = r#"[scene]
kind = "hard-spheres"
t_end = 0.05
seed = 0

[stepping]
dt = 1e-3

[gravity]
g = [0.0, 0.0, -9.81]            # m/s²

[material]
eps_n = 0.9

[output]
times = [0.0, 0.05]
every = 0.01

[[particle]]
mass = 1.0
radius = 0.05
position = [0.0, 0.0, 0.5]

[[wall]]
type = "plane"
origin = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]
oscillation = { amplitude = 0.01, omega = 60.0, phase = 0.0, direction = [0.0, 0.0, 1.0] }

[[wall]]
type = "cylinder"
origin = [0.0, 0.0, 0.5]
axis = [0.0, 1.0, 0.0]
radius = 1.0
spin = 1.0
"#;

/// The old names of [`OLD_SOFT`] and [`OLD_HARD`], each with the name it is read as.
const SOFT_RENAMES: [(&str, &str); 6] = [
    ("[integrator]", "[stepping]"),
    ("[contact]", "[material]"),
    (
        "wall[0].oscillation.frequency = 5.0 Hz",
        "wall[0].oscillation.angular_frequency = 31.41592653589793 rad/s",
    ),
    (
        "wall[0].oscillation.amplitude = [0.0, 0.0, 0.01] (a vector)",
        "wall[0].oscillation.amplitude = 0.01 m",
    ),
    (
        "wall[1].oscillation.frequency = 0.3 Hz",
        "wall[1].oscillation.angular_frequency",
    ),
    (
        "wall[1].oscillation.amplitude = [-0.02, 0.0, 0.0] (a vector)",
        "direction = [-1.0, 0.0, 0.0]",
    ),
];
const HARD_RENAMES: [(&str, &str); 7] = [
    ("gravity.g", "gravity.uniform"),
    ("wall[0].type", "wall[0].kind"),
    ("wall[0].origin", "wall[0].point"),
    ("wall[0].axis", "wall[0].normal"),
    ("wall[0].oscillation.omega", "wall[0].oscillation.angular_frequency"),
    ("wall[1].type", "wall[1].kind"),
    ("wall[1].origin", "wall[1].centre"),
];

/// A parsed scene without what differs between an old text and its migration (the text and its warnings), as a
/// string that holds every number to the bit (`Debug` of `f64` reads back exactly).
fn soft_value(text: &str) -> (String, Vec<String>) {
    let mut s = soft::scene::parse_soft_scene(text, "s.toml", Some(Path::new("."))).unwrap_or_else(|e| panic!("{e}"));
    let warnings = std::mem::take(&mut s.warnings);
    s.source = String::new();
    (format!("{s:?}"), warnings)
}

fn hard_value(text: &str) -> (String, Vec<String>) {
    let mut s = hard::scene::parse_hard_scene(text, "h.toml", Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    let warnings = std::mem::take(&mut s.warnings);
    s.source = String::new();
    (format!("{s:?}"), warnings)
}

/// Old names are read as the new ones, each with one warning line naming the old key and the new one.
#[test]
fn old_names_still_parse_with_one_warning_each() {
    for (value, renames) in [
        (soft_value(OLD_SOFT), &SOFT_RENAMES[..]),
        (hard_value(OLD_HARD), &HARD_RENAMES[..]),
    ] {
        let (_, warnings) = value;
        assert_eq!(warnings.len(), renames.len(), "{warnings:#?}");
        for ((old, new), w) in renames.iter().zip(&warnings) {
            assert!(
                w.contains(old) && w.contains(new) && w.contains("is an old name"),
                "{w}"
            );
            assert_eq!(w.lines().count(), 1, "{w}");
        }
    }
}

/// `check` and `run` print those warnings.
#[test]
fn check_and_run_print_the_old_name_warnings() {
    let dir = temp_dir("vocab-warn");
    std::fs::write(dir.join("old.toml"), OLD_HARD).unwrap();
    let check = rubblepile(&dir, &["check", "old.toml"]);
    assert!(check.status.success(), "{}", common::describe(&check));
    let stderr = String::from_utf8_lossy(&check.stderr);
    assert!(
        stderr.contains("warning: old.toml: gravity.g is an old name, read as gravity.uniform"),
        "{stderr}"
    );
    let run = rubblepile(&dir, &["run", "old.toml", "--out", "out", "--no-progress"]);
    assert!(run.status.success(), "{}", common::describe(&run));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("wall[1].origin is an old name, read as wall[1].centre"),
        "{stderr}"
    );
}

/// `check --migrate` prints a text that reads with no warning as the same scene, to the bit; with `--out` it writes
/// that file (an existing one only with `--force`); over the scene itself only with `--force`.
#[test]
fn check_migrate_gives_the_same_scene_without_warnings() {
    let dir = temp_dir("vocab-migrate");
    for (name, old) in [("soft.toml", OLD_SOFT), ("hard.toml", OLD_HARD)] {
        std::fs::write(dir.join(name), old).unwrap();
        let out = rubblepile(&dir, &["check", "--migrate", name]);
        assert!(out.status.success(), "{}", common::describe(&out));
        let new = String::from_utf8(out.stdout).unwrap();
        let value = |t: &str| {
            if name == "soft.toml" {
                soft_value(t)
            } else {
                hard_value(t)
            }
        };
        let (before, _) = value(old);
        let (after, warnings) = value(&new);
        assert!(warnings.is_empty(), "{name}: {warnings:?}");
        assert_eq!(after, before, "{name}: the migrated scene differs");
        assert!(migrate::migrate(&new).renames.is_empty());
        // Comments stay.
        assert!(new.contains("# m/s²"), "{new}");
        // Stdout only: the scene is untouched.
        assert_eq!(std::fs::read_to_string(dir.join(name)).unwrap(), old);

        let to = format!("new_{name}");
        let out = rubblepile(&dir, &["check", "--migrate", name, "--out", &to]);
        assert!(out.status.success(), "{}", common::describe(&out));
        assert_eq!(std::fs::read_to_string(dir.join(&to)).unwrap(), new);
        let again = rubblepile(&dir, &["check", "--migrate", name, "--out", &to]);
        assert_eq!(again.status.code(), Some(2), "{}", common::describe(&again));
        assert!(String::from_utf8_lossy(&again.stderr).contains("--force"));
        let forced = rubblepile(&dir, &["check", "--migrate", name, "--out", &to, "--force"]);
        assert!(forced.status.success(), "{}", common::describe(&forced));

        let in_place = rubblepile(&dir, &["check", "--migrate", name, "--force"]);
        assert!(in_place.status.success(), "{}", common::describe(&in_place));
        assert_eq!(std::fs::read_to_string(dir.join(name)).unwrap(), new);
        let check = rubblepile(&dir, &["check", name]);
        assert!(
            check.status.success() && check.stderr.is_empty(),
            "{}",
            common::describe(&check)
        );
    }
    // --out and --force need --migrate.
    let out = rubblepile(&dir, &["check", "soft.toml", "--out", "x.toml"]);
    assert_eq!(out.status.code(), Some(2));
}

/// The `*.toml` files below `dir` (skipping build outputs).
fn tomls(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let p = entry.path();
        if p.is_dir() && p.file_name().is_some_and(|n| n != "target") {
            tomls(&p, out);
        } else if p.extension().is_some_and(|e| e == "toml") {
            out.push(p);
        }
    }
}

/// Every granular scene under `targets/`, `analysis/` and `tests/` reads by the current names alone: no old name
/// to migrate, and the strict schema (unknown keys refused) takes it.
#[test]
fn every_granular_scene_of_the_repository_uses_the_current_names() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for d in ["targets", "analysis", "tests"] {
        tomls(&root.join(d), &mut files);
    }
    let mut checked = 0;
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let Ok(table) = text.parse::<toml::Table>() else {
            continue;
        };
        let kind = table.get("scene").and_then(|s| s.get("kind")).and_then(|k| k.as_str());
        let strict = match kind {
            Some(soft::scene::KIND) => toml::from_str::<soft::scene::SoftSceneFile>(&text).map(|_| ()),
            Some(hard::scene::KIND) => toml::from_str::<hard::scene::HardSceneFile>(&text).map(|_| ()),
            _ => continue,
        };
        let renames = migrate::migrate(&text).renames;
        assert!(renames.is_empty(), "{}: old names {renames:?}", f.display());
        strict.unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        checked += 1;
    }
    assert!(checked > 100, "only {checked} granular scenes found");
}
