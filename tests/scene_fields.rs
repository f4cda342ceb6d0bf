//! The scene-file field reference (`rubblepile check --explain`, `rubblepile::io::scene_fields`), whose rows are
//! written on the scene structs' fields and collected by `#[derive(SceneFields)]` (which refuses a field without a
//! row at compile time): the printed reference of each engine is the committed one (`tests/data/explain/`), and
//! every bound a row prints is the one the validator enforces (a value just past it is refused naming the field and
//! the row's range; a closed end is accepted), and every printed numeric default is the parser's.
//!
//! To re-record the expected references after an intended change: `RUBBLEPILE_BLESS_EXPLAIN=1 cargo test --release
//! --test scene_fields`.

use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

use rubblepile::driver::SceneKind;
use rubblepile::io::scene_fields::Range;
use rubblepile::named::Named;

/// `check --explain KIND` against `tests/data/explain/KIND.txt`, line by line; each key and table once.
#[test]
fn explain_is_the_committed_reference() {
    for kind in SceneKind::ALL {
        let name = kind.name();
        let out = rubblepile(&["check", "--explain", name]);
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let text = String::from_utf8(out.stdout).unwrap();
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/data/explain/{name}.txt"));
        if std::env::var_os("RUBBLEPILE_BLESS_EXPLAIN").is_some() {
            std::fs::write(&path, &text).unwrap();
        }
        let expected = std::fs::read_to_string(&path).unwrap();
        for (n, (got, want)) in text.lines().zip(expected.lines()).enumerate() {
            assert_eq!(got, want, "{name}: line {} differs from {}", n + 1, path.display());
        }
        assert_eq!(text.lines().count(), expected.lines().count(), "{name}: line count");
        let reference = kind.reference();
        let keys: BTreeSet<&str> = reference.fields.iter().map(|f| f.key).collect();
        assert_eq!(keys.len(), reference.fields.len(), "{name}: a key has two rows");
        let tables: BTreeSet<&str> = reference.tables.iter().map(|t| t.key).collect();
        assert_eq!(tables.len(), reference.tables.len(), "{name}: a table has two rows");
        // Every row lives in a table that has a row (or at the top level).
        for f in &reference.fields {
            let table = f.key.rsplit_once('.').map_or("", |(t, _)| t);
            assert!(
                table.is_empty() || tables.contains(table),
                "{name}: {} has no table row",
                f.key
            );
        }
    }
}

/// The rows a validator reads are the struct's own consts, under the dotted key serde reads (renames applied).
#[test]
fn rows_are_the_struct_fields() {
    use rubblepile::ellipsoid::scene::{DissipationSpec, GravitySpec};
    use rubblepile::granular::soft::spinup::SpinupSection;
    assert_eq!(GravitySpec::G.key, "physics.gravity.G");
    assert_eq!(DissipationSpec::F0.key, "physics.dissipation.F0");
    assert_eq!(SpinupSection::PERIOD_START_H.key, "spinup.T_start");
    let reference = SceneKind::Ellipsoids.reference();
    assert_eq!(reference.field("physics.gravity.theta"), Some(&GravitySpec::THETA));
}

const ELLIPSOIDS: &str = r#"
[scene]
kind = "ellipsoids"
t_end = 60.0
[model]
kappa = 10.0
[physics]
gravity = { G = 6.674e-11, theta = 0.5 }
contact = { cutoff = 1e-16 }
dissipation = { F0 = 0.01 }
flyby = { mass = 5.97e24, radius = 6.371e6, q = 3.8e7, v_inf = 5800.0, t_perigee = 30.0 }
[integrator]
rtol = 1e-10
atol = 1e-10
[output]
every = 1.0
[[body]]
axes = [3.0, 2.0, 1.5]
mass = 30000.0
position = [0.0, 0.0, 0.0]
[[body]]
axes = [2.0, 1.5, 1.0]
density = 2000.0
position = [5.5, 0.5, 0.0]
"#;

const CALIBRATED: &str = r#"
[scene]
kind = "ellipsoids"
t_end = 60.0
[model]
calibrate = { beta = 10.0, v = 0.1 }
[physics]
gravity = {}
contact = {}
[output]
every = 1.0
[[body]]
axes = [3.0, 2.0, 1.5]
mass = 30000.0
position = [0.0, 0.0, 0.0]
[[body]]
axes = [2.0, 1.5, 1.0]
mass = 20000.0
position = [5.5, 0.5, 0.0]
"#;

const SOFT: &str = r#"
[scene]
kind = "soft-spheres"
t_end = 0.01
[stepping]
dt = 7e-5
[material]
k_n = 4.2e8
eps_n = 0.55
eps_t = 0.55
mu_s = 1.0
mu_t = 1.3
mu_r = 1.05
beta = 0.5
max_start_overlap = 0.05
[gravity]
self = "tree"
theta = 0.5
G = 6.674e-11
[output]
every = 0.001
[[particle]]
radius = 0.5
density = 2000.0
position = [0.0, 0.0, 0.0]
[[particle]]
radius = 0.5
density = 2000.0
position = [1.0, 0.0, 0.0]
[spinup]
T_start = 10.0
T_inter = 5.0
T_final = 4.0
t_start = 0.0
t_inter = 0.005
t_final = 0.01
rest_length = 0.0
release_axis_ratio = 0.1
release_packing = 0.01
interior_depth = 0.1
interior_ramp = 0.1
"#;

const HARD: &str = r#"
[scene]
kind = "hard-spheres"
t_end = 2.0
[stepping]
dt = 1e-3
collapse_speed = 1e-4
max_events_per_step = 10000000
skin_steps = 16.0
[material]
eps_n = 0.5
eps_t = 1.0
[output]
every = 0.01
[[particle]]
mass = 1.0
radius = 0.05
position = [0.0, 0.0, 0.5]
"#;

/// Parses and validates a scene text of `kind` (the message of the error on failure).
fn validate(kind: SceneKind, text: &str) -> Result<(), String> {
    let dir = Path::new(".");
    match kind {
        SceneKind::Ellipsoids => rubblepile::ellipsoid::scene::parse_scene(text, "t.toml", Some(dir)).map(|_| ()),
        SceneKind::SoftSpheres => {
            rubblepile::granular::soft::scene::parse_soft_scene(text, "t.toml", Some(dir)).map(|_| ())
        }
        SceneKind::HardSpheres => rubblepile::granular::hard::scene::parse_hard_scene(text, "t.toml", dir).map(|_| ()),
    }
    .map_err(|e| e.to_string())
}

/// The base text with the value at dotted `key` replaced (None when the base has no such key).
fn with_value(base: &str, key: &str, value: toml::Value) -> Option<String> {
    let mut table: toml::Table = base.parse().expect("base scene is TOML");
    let (path, last) = key.rsplit_once('.').unwrap_or(("", key));
    let mut t = &mut table;
    for part in path.split('.').filter(|p| !p.is_empty()) {
        t = t.get_mut(part)?.as_table_mut()?;
    }
    let slot = t.get_mut(last)?;
    *slot = value;
    Some(toml::to_string(&table).expect("a table serialises"))
}

/// The nearest f64 above (`up`) or below `x`.
fn next(x: f64, up: bool) -> f64 {
    if x == 0.0 {
        return if up { f64::from_bits(1) } else { -f64::from_bits(1) };
    }
    let bits = x.to_bits();
    f64::from_bits(if (x > 0.0) == up { bits + 1 } else { bits - 1 })
}

/// For every bounded row of `kind` whose key the base holds (outside arrays of tables): each finite end's nearest
/// value outside is refused with one line naming the key (and, for an interval, printing the row's range), and a
/// closed end is accepted. Returns the keys tested.
fn bounds_enforced(kind: SceneKind, base: &str) -> Vec<&'static str> {
    validate(kind, base).unwrap_or_else(|e| panic!("the base scene is valid: {e}"));
    let reference = kind.reference();
    let arrays: Vec<&str> = reference.tables.iter().filter(|t| t.array).map(|t| t.key).collect();
    let mut tested = Vec::new();
    for row in &reference.fields {
        if arrays.iter().any(|a| row.key.starts_with(&format!("{a}."))) {
            continue;
        }
        let base_value = {
            let table: toml::Table = base.parse().unwrap();
            row.key
                .split('.')
                .try_fold(toml::Value::Table(table), |v, part| v.get(part).cloned())
        };
        let Some(base_value) = base_value else { continue };
        let integer = base_value.is_integer();
        let number = |x: f64| {
            if integer {
                toml::Value::Integer(x as i64)
            } else {
                toml::Value::Float(x)
            }
        };
        let (outside, inside): (Vec<f64>, Vec<f64>) = match row.range {
            Range::Positive => (vec![0.0, 0.5e-300, f64::NAN], vec![]),
            Range::NonNegative => (vec![next(0.0, false), -1.0, f64::NAN], vec![]),
            Range::Interval {
                lo,
                lo_closed,
                hi,
                hi_closed,
            } => {
                let step = |x: f64, up: bool| {
                    if integer {
                        x + if up { 1.0 } else { -1.0 }
                    } else {
                        next(x, up)
                    }
                };
                let mut outside = vec![f64::NAN];
                let mut inside = vec![];
                if lo.is_finite() {
                    outside.push(if lo_closed { step(lo, false) } else { lo });
                    if lo_closed {
                        inside.push(lo);
                    }
                }
                if hi.is_finite() {
                    outside.push(if hi_closed { step(hi, true) } else { hi });
                    if hi_closed {
                        inside.push(hi);
                    }
                }
                (outside, inside)
            }
            Range::Rule(_) => continue,
        };
        for x in outside.into_iter().filter(|x| !(integer && x.is_nan())) {
            let text = with_value(base, row.key, number(x)).expect("the key is in the base");
            let message = validate(kind, &text).expect_err(&format!("{} = {x:e} is outside {}", row.key, row.range));
            assert!(
                message.contains(&format!("{}: ", row.key)),
                "{} = {x:e}: the error does not name the field: {message}",
                row.key
            );
            if matches!(row.range, Range::Interval { .. }) {
                assert!(
                    message.contains(&row.range.to_string()),
                    "{} = {x:e}: the error does not print the reference's range {}: {message}",
                    row.key,
                    row.range
                );
            }
            assert_eq!(message.lines().count(), 1, "{message}");
        }
        for x in inside {
            let text = with_value(base, row.key, number(x)).expect("the key is in the base");
            validate(kind, &text)
                .unwrap_or_else(|e| panic!("{} = {x:e} is inside {}: refused: {e}", row.key, row.range));
        }
        tested.push(row.key);
    }
    tested
}

#[test]
fn ellipsoid_bounds_are_the_validators() {
    let mut tested = bounds_enforced(SceneKind::Ellipsoids, ELLIPSOIDS);
    tested.extend(bounds_enforced(SceneKind::Ellipsoids, CALIBRATED));
    let expected = [
        "scene.t_end",
        "model.kappa",
        "physics.gravity.G",
        "physics.gravity.theta",
        "physics.contact.cutoff",
        "physics.dissipation.F0",
        "physics.flyby.mass",
        "physics.flyby.radius",
        "physics.flyby.q",
        "physics.flyby.v_inf",
        "integrator.rtol",
        "integrator.atol",
        "scene.t_end",
        "model.calibrate.beta",
        "model.calibrate.v",
    ];
    assert_eq!(tested, expected);
}

#[test]
fn soft_sphere_bounds_are_the_validators() {
    let tested = bounds_enforced(SceneKind::SoftSpheres, SOFT);
    let expected = [
        "scene.t_end",
        "material.k_n",
        "material.eps_n",
        "material.eps_t",
        "material.mu_s",
        "material.mu_t",
        "material.mu_r",
        "material.beta",
        "material.max_start_overlap",
        "gravity.theta",
        "gravity.G",
        "spinup.T_start",
        "spinup.T_inter",
        "spinup.T_final",
        "spinup.t_start",
        "spinup.t_inter",
        "spinup.t_final",
        "spinup.rest_length",
        "spinup.release_axis_ratio",
        "spinup.release_packing",
        "spinup.interior_depth",
        "spinup.interior_ramp",
    ];
    assert_eq!(tested, expected);
}

#[test]
fn hard_sphere_bounds_are_the_validators() {
    let tested = bounds_enforced(SceneKind::HardSpheres, HARD);
    let expected = [
        "scene.t_end",
        "stepping.collapse_speed",
        "stepping.max_events_per_step",
        "stepping.skin_steps",
        "material.eps_n",
        "material.eps_t",
    ];
    assert_eq!(tested, expected);
}

/// For every row outside arrays of tables whose default is a number and whose key the base holds: the value the
/// parser's schema takes with the key removed (serde's default; keys the validator defaults, read as `None` here,
/// are left out) equals the row's default. Returns the keys compared.
fn serde_defaults_are_the_references<T: serde::de::DeserializeOwned + serde::Serialize>(
    kind: SceneKind,
    base: &str,
) -> Vec<&'static str> {
    let reference = kind.reference();
    let mut compared = Vec::new();
    for row in &reference.fields {
        let Some(Ok(default)) = row.default.split_whitespace().next().map(str::parse::<f64>) else {
            continue;
        };
        let mut table: toml::Table = base.parse().unwrap();
        if !remove(&mut table, row.key) {
            continue;
        }
        let file: T = toml::from_str(&toml::to_string(&table).unwrap())
            .unwrap_or_else(|e| panic!("{} removed: the schema refuses the scene: {e}", row.key));
        let value = toml::Value::try_from(&file).unwrap();
        let Some(got) = row.key.split('.').try_fold(value, |v, part| v.get(part).cloned()) else {
            continue;
        };
        let got = got.as_float().or(got.as_integer().map(|i| i as f64)).unwrap();
        assert_eq!(
            got, default,
            "{}: the parser's default is not the reference's {}",
            row.key, row.default
        );
        compared.push(row.key);
    }
    compared
}

/// Removes the value at dotted `key` from `table`; false when there is none.
fn remove(table: &mut toml::Table, key: &str) -> bool {
    match key.split_once('.') {
        None => table.remove(key).is_some(),
        Some((head, rest)) => match table.get_mut(head).and_then(toml::Value::as_table_mut) {
            Some(inner) => remove(inner, rest),
            None => false,
        },
    }
}

#[test]
fn printed_defaults_are_the_parsers() {
    use rubblepile::granular::{hard, soft};
    let soft = serde_defaults_are_the_references::<soft::scene::SoftSceneFile>(SceneKind::SoftSpheres, SOFT);
    assert_eq!(
        soft,
        [
            "material.eps_n",
            "material.eps_t",
            "material.mu_s",
            "material.mu_t",
            "material.mu_r",
            "material.beta",
            "material.max_start_overlap",
            "spinup.rest_length",
            "spinup.release_axis_ratio",
            "spinup.release_packing",
        ]
    );
    let hard = serde_defaults_are_the_references::<hard::scene::HardSceneFile>(SceneKind::HardSpheres, HARD);
    assert_eq!(
        hard,
        [
            "stepping.collapse_speed",
            "stepping.max_events_per_step",
            "stepping.skin_steps",
            "material.eps_n",
            "material.eps_t",
        ]
    );
}

/// The bound of a row in an array of tables is enforced too, under the indexed field name: a hard-sphere
/// particle's eps_t just below the row's −1, and a soft-sphere particle's radius of 0.
#[test]
fn array_rows_bounds_are_the_validators() {
    let row = SceneKind::HardSpheres.reference().field("particle.eps_t").unwrap();
    let text = HARD.replace(
        "radius = 0.05\n",
        &format!("radius = 0.05\neps_t = {:e}\n", next(-1.0, false)),
    );
    let message = validate(SceneKind::HardSpheres, &text).unwrap_err();
    assert!(
        message.contains(&format!("particle[0].eps_t: must be in {}", row.range)),
        "{message}"
    );
    assert_eq!(row.range.to_string(), "[-1, 1]");

    let text = SOFT.replacen("radius = 0.5", "radius = 0.0", 1);
    let message = validate(SceneKind::SoftSpheres, &text).unwrap_err();
    assert!(message.contains("particle[0].radius: must be > 0"), "{message}");
}

fn rubblepile(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_rubblepile"))
        .args(args)
        .output()
        .expect("runs")
}

#[test]
fn check_explain_prints_the_reference() {
    let out = rubblepile(&["check", "--explain", "soft-spheres"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    let k_n = text
        .lines()
        .find(|l| l.starts_with("material.k_n "))
        .unwrap_or_else(|| panic!("no material.k_n line in:\n{text}"));
    let columns: Vec<&str> = k_n.split("  ").map(str::trim).filter(|c| !c.is_empty()).collect();
    assert_eq!(
        &columns[..4],
        ["material.k_n", "N/m", "required", ">= 1e-300, finite"],
        "{k_n}"
    );
    assert!(text.contains("\n[material]: "), "{text}");
    assert!(text.contains("\n[[particle]]: "), "{text}");
    assert!(text.contains("\n[spinup]: "), "{text}");
    let eps = text.lines().find(|l| l.starts_with("material.eps_n ")).unwrap();
    assert!(eps.contains("0.55") && eps.contains("(0, 1]"), "{eps}");
    // One line per key: the printed table is the whole reference.
    let reference = SceneKind::SoftSpheres.reference();
    for f in &reference.fields {
        assert_eq!(
            text.lines().filter(|l| l.starts_with(&format!("{} ", f.key))).count(),
            1,
            "{} in:\n{text}",
            f.key
        );
    }

    // Without a kind: all three, each under its own heading.
    let out = rubblepile(&["check", "--explain"]);
    assert!(out.status.success());
    let all = String::from_utf8(out.stdout).unwrap();
    for kind in ["ellipsoids", "soft-spheres", "hard-spheres"] {
        assert!(all.contains(&format!("# kind = \"{kind}\"\n")), "{kind}");
    }
    assert!(
        all.contains("\n[physics]: ") && all.contains("\n[physics.gravity]: "),
        "{all}"
    );
    assert!(
        all.lines()
            .any(|l| l.starts_with("physics.dissipation.F0 ") && l.contains("s m^-2"))
    );

    // Each kind by its `scene.kind` name.
    for kind in SceneKind::ALL {
        let name = kind.reference().kind;
        let out = rubblepile(&["check", "--explain", name]);
        assert!(out.status.success(), "{name}");
        assert!(
            String::from_utf8(out.stdout)
                .unwrap()
                .starts_with(&format!("# kind = \"{name}\"\n"))
        );
    }

    // An unknown kind is bad input: exit code 2, the kinds named.
    let out = rubblepile(&["check", "--explain", "rigid-bodies"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("hard-spheres"));
}
