//! Golden outputs of the run driver: one run per engine (ellipsoids on the four-fragment scene that was the built-in
//! default until the default became an impact, soft spheres,
//! hard spheres), an impact and a spin-up run, compared file by file with the outputs recorded before the three
//! drivers were merged into one (`tests/golden/<case>/expected/`). Every byte must match except what measures the
//! machine rather than the physics: the `wall_seconds` column and field, the hard-sphere engine's
//! `events_per_second` (events per wall-clock second), and the directory of the absolute input path the scene copy
//! records (each case runs in a fresh temporary directory; the file's name is compared).
//!
//! To re-record after an intended change of the outputs: `RUBBLEPILE_BLESS_GOLDEN=1 cargo test --release --test
//! golden`, then review the diff of `tests/golden/` before committing it.

mod common;
use common::{rubblepile, temp_dir};
use rubblepile::io::run_lock::is_lock_file;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Columns (CSV) and keys (JSON) that depend on the machine's speed.
const MACHINE_DEPENDENT: [&str; 2] = ["wall_seconds", "events_per_second"];

/// A scene copy's line `particles_file = "/tmp/…/ball.csv"` (an absolute input path, crate::io::standalone) as
/// `particles_file = "ball.csv"`; other lines as they are.
fn input_file_name(line: &str) -> String {
    for key in ["particles_file", "bodies_file"] {
        if let Some(value) = line.strip_prefix(key).and_then(|r| r.trim_start().strip_prefix('=')) {
            let path = value.trim().trim_matches('"');
            if Path::new(path).is_absolute() {
                let name = Path::new(path).file_name().unwrap().to_string_lossy();
                return format!("{key} = \"{name}\"");
            }
        }
    }
    line.to_string()
}

/// The text of an output file with the machine-dependent columns or lines removed.
fn scrub(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    if path.file_name().is_some_and(|f| f == "scene.toml") {
        return text.lines().map(|l| format!("{}\n", input_file_name(l))).collect();
    }
    if path.extension().is_some_and(|e| e == "json") {
        return text
            .lines()
            .filter(|l| {
                let key = l.trim_start();
                !MACHINE_DEPENDENT.iter().any(|k| key.starts_with(&format!("\"{k}\"")))
            })
            .map(|l| format!("{l}\n"))
            .collect();
    }
    if path.extension().is_some_and(|e| e == "csv") {
        let mut lines = text.lines();
        let Some(header) = lines.next() else {
            return text;
        };
        let names: Vec<&str> = header.split(',').collect();
        let keep: Vec<bool> = names.iter().map(|n| !MACHINE_DEPENDENT.contains(n)).collect();
        let filter = |l: &str| -> String {
            let cells: Vec<&str> = l.split(',').collect();
            if cells.len() != keep.len() {
                return format!("{l}\n");
            }
            let kept: Vec<&str> = cells.iter().zip(&keep).filter(|(_, k)| **k).map(|(c, _)| *c).collect();
            format!("{}\n", kept.join(","))
        };
        return std::iter::once(header).chain(lines).map(filter).collect();
    }
    text
}

/// Every file below `dir`, as paths relative to it, sorted.
fn files(dir: &Path) -> Vec<PathBuf> {
    fn walk(base: &Path, dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let p = entry.unwrap().path();
            if p.is_dir() {
                walk(base, &p, out);
            } else {
                out.push(p.strip_prefix(base).unwrap().to_path_buf());
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// Writes the ~90-sphere HCP ball of the soft-sphere cases (r = 1 m, 1000 kg/m³).
fn write_ball(dir: &Path) {
    let mut csv = String::from("t,id,mass,radius,x,y,z,vx,vy,vz,wx,wy,wz\n");
    let m = 1000.0 * 4.0 / 3.0 * std::f64::consts::PI;
    for (k, p) in rubblepile::geometry::lattice::hcp_centres(1.0, 5.0).iter().enumerate() {
        csv += &format!("0,{k},{m},1.0,{},{},{},0,0,0,0,0,0\n", p.x, p.y, p.z);
    }
    std::fs::write(dir.join("ball.csv"), csv).unwrap();
}

/// Runs one case: `args` (with `OUT` replaced by the output directory) in `cwd`, then compares (or, when blessing,
/// records) every output file.
fn check_case(name: &str, cwd: &Path, args: &[&str]) {
    let out = temp_dir(&format!("golden-{name}")).join("out");
    let out_s = out.display().to_string();
    let args: Vec<&str> = args
        .iter()
        .map(|a| if *a == "OUT" { out_s.as_str() } else { a })
        .collect();
    let o = rubblepile(cwd, &args);
    assert!(
        o.status.success(),
        "{name}: {args:?} failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let expected_dir = root().join("tests/golden").join(name).join("expected");
    let produced: Vec<PathBuf> = files(&out)
        .into_iter()
        // The checkpoint, the manifest of checksums and the directory's lock files are no outputs of the physics.
        .filter(|p| {
            p.file_name()
                .is_some_and(|f| f != "checkpoint.json" && f != "manifest.txt" && !is_lock_file(f))
        })
        .collect();
    if std::env::var_os("RUBBLEPILE_BLESS_GOLDEN").is_some() {
        if expected_dir.exists() {
            std::fs::remove_dir_all(&expected_dir).unwrap();
        }
        for rel in &produced {
            let dst = expected_dir.join(rel);
            std::fs::create_dir_all(dst.parent().unwrap()).unwrap();
            std::fs::write(&dst, scrub(&out.join(rel))).unwrap();
        }
        return;
    }
    let expected = files(&expected_dir);
    assert_eq!(
        produced, expected,
        "{name}: the run wrote other files than the golden run"
    );
    compare(name, &out, &expected_dir, &expected);
}

/// Compares the files `rels` of the run in `out` with those recorded in `expected_dir` (machine-dependent parts
/// scrubbed), naming the first line that differs.
fn compare(name: &str, out: &Path, expected_dir: &Path, rels: &[PathBuf]) {
    for rel in rels {
        let got = scrub(&out.join(rel));
        let want = std::fs::read_to_string(expected_dir.join(rel)).unwrap();
        if got != want {
            let line = got
                .lines()
                .zip(want.lines())
                .position(|(a, b)| a != b)
                .unwrap_or(got.lines().count().min(want.lines().count()));
            panic!(
                "{name}: {} differs from the golden output at line {}:\n  got:  {}\n  want: {}",
                rel.display(),
                line + 1,
                got.lines().nth(line).unwrap_or("<end>"),
                want.lines().nth(line).unwrap_or("<end>")
            );
        }
    }
}

/// A temporary copy of `tests/golden/<name>` (its scene and inputs) with the HCP ball written beside it.
fn case_dir(name: &str) -> PathBuf {
    let dir = temp_dir(&format!("golden-in-{name}"));
    let src = root().join("tests/golden").join(name);
    for entry in std::fs::read_dir(&src).unwrap() {
        let p = entry.unwrap().path();
        if p.is_file() {
            std::fs::copy(&p, dir.join(p.file_name().unwrap())).unwrap();
        }
    }
    write_ball(&dir);
    dir
}

#[test]
fn golden_ellipsoids_four_fragments() {
    check_case(
        "ellipsoids_four_fragments",
        &root(),
        &[
            "run",
            "targets/examples/four_fragments.toml",
            "--out",
            "OUT",
            "--no-progress",
            "--checkpoint-every-s",
            "0",
        ],
    );
}

#[test]
fn golden_impact_n30() {
    check_case(
        "impact_n30",
        &root(),
        &[
            "impact",
            "--target",
            "targets/N30_T4.csv",
            "--t-end-s",
            "300",
            "--every-s",
            "20",
            "--out",
            "OUT",
            "--no-progress",
            "--checkpoint-every-s",
            "0",
        ],
    );
}

/// The impact's scene copy as `rubblepile impact` wrote it before the scene was serialised from its value (by
/// `format!`, with inline tables), recorded in `tests/golden/impact_n30/expected/` until then.
const IMPACT_N30_SCENE_OLD_LAYOUT: &str = r#"# Impact of P2 (21.21 km, 5.0 km/s) on targets/N30_T4.csv at zeta = 45 deg; Q = 1.495e9 erg/g
# Generated by `rubblepile impact`; the same run: `rubblepile run scene.toml --out OTHER_DIR`.
[scene]
kind = "ellipsoids"
t_end = 300.0
seed = 1
bodies_file = "initial_bodies.csv"

[model]
calibrate = { beta = 10.0, v = 5000.0, reading = "printed" }
inertia = "gaussian"

[physics]
gravity = {}
contact = {}
dissipation = { F0 = 1e-6 }

[integrator]
method = "bulirsch-stoer"
rtol = 1e-6
atol = 1e-6

[output]
times = [0.0, 100.0, 300.0]
every = 20.0
track = [30]
"#;

/// The impact's scene copy, serialised from the scene value, holds the values of the layout written before
/// ([`IMPACT_N30_SCENE_OLD_LAYOUT`]), and `rubblepile run` of either (with the impact's `initial_bodies.csv` beside
/// it) reproduces the golden impact bit for bit.
#[test]
fn golden_impact_n30_scene_copy_reruns_bit_identically() {
    use rubblepile::ellipsoid::scene::parse_toml;
    let expected_dir = root().join("tests/golden/impact_n30/expected");
    let new_layout = std::fs::read_to_string(expected_dir.join("scene.toml")).unwrap();
    assert_ne!(new_layout, IMPACT_N30_SCENE_OLD_LAYOUT);
    assert_eq!(
        parse_toml(&new_layout, "new").unwrap(),
        parse_toml(IMPACT_N30_SCENE_OLD_LAYOUT, "old").unwrap()
    );
    for (tag, scene) in [("new", new_layout.as_str()), ("old", IMPACT_N30_SCENE_OLD_LAYOUT)] {
        let dir = temp_dir(&format!("golden-rerun-{tag}"));
        std::fs::write(dir.join("scene.toml"), scene).unwrap();
        std::fs::copy(expected_dir.join("initial_bodies.csv"), dir.join("initial_bodies.csv")).unwrap();
        let out = dir.join("out");
        let args = [
            "run",
            "scene.toml",
            "--out",
            "out",
            "--no-progress",
            "--checkpoint-every-s",
            "0",
        ];
        let o = rubblepile(&dir, &args);
        assert!(o.status.success(), "{tag}: {}", String::from_utf8_lossy(&o.stderr));
        // every output of the physics, and (from the new layout) the scene copy, as the impact wrote them
        let rels: Vec<PathBuf> = files(&expected_dir)
            .into_iter()
            .filter(|p| !["impact.json", "initial_bodies.csv"].iter().any(|f| p.ends_with(f)))
            .filter(|p| tag == "new" || !p.ends_with("scene.toml"))
            .collect();
        compare(
            &format!("impact_n30 rerun of the {tag} layout"),
            &out,
            &expected_dir,
            &rels,
        );
    }
}

/// A case whose scene (and inputs) sit in `tests/golden/<name>/`, run with `rubblepile run scene.toml`.
fn check_scene_case(name: &str) {
    let dir = case_dir(name);
    check_case(
        name,
        &dir,
        &[
            "run",
            "scene.toml",
            "--out",
            "OUT",
            "--no-progress",
            "--checkpoint-every-s",
            "0",
        ],
    );
}

#[test]
fn golden_soft_spheres() {
    check_scene_case("soft_ball");
}

#[test]
fn golden_spinup() {
    check_scene_case("spinup_ball");
}

#[test]
fn golden_hard_spheres() {
    check_scene_case("hard_box");
}
