//! Property test of issue 38 ("nothing lost, nothing hung"): numeric fields of valid scenes of the three engines
//! (`tests/bad_input/{ellipsoids,soft,hard}.toml`) are mutated to extremes — ±1e308, ±1e-320 (subnormal), 0, NaN,
//! ±inf, a negative or a much larger or smaller value, an array of the wrong length, an integer out of range — and
//! every mutated scene is given to the binary, each invocation under a wall-clock limit (the child is killed at
//! the limit and the case fails). `rubblepile check` must end with exit 0 (accepted) or exit 2 and exactly one
//! one-line `error: scene.toml: …`; an accepted scene is then run (`rubblepile run`), which must complete (exit 0)
//! or fail with exit 1 and one `error: run failed: …` naming a cause, or refuse it with exit 2 as above. Never a
//! panic, a signal (an abort on allocation), a second error line, or a hang. A scene accepted with the work warning
//! (`warning: … more than 1e9 …`: e.g. a spin multiplied by 1e10) is a legitimate big run that says so; it is
//! counted and not run (`crawling_scenes_are_named_by_a_warning` checks that its run starts with the warning).
//!
//! The cases come from proptest with a fixed ChaCha seed ([`TestRng::deterministic_rng`]), so CI sees the same
//! scenes every time; a failure is shrunk (a few iterations) and reported with the mutated scene.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};

mod common;

/// Mutated scenes per run of the test (each is checked; the accepted ones are also run).
const CASES: u32 = 1200;

/// Wall-clock limit of one `check` (s): validation reads one small file and evaluates one right-hand side.
const CHECK_LIMIT_S: f64 = 20.0;

/// Wall-clock limit of one `run` of an accepted scene (s): the base scenes run in well under a second, and a
/// mutation that makes a run crawl must have been refused (or warned about and bounded) by validation.
const RUN_LIMIT_S: f64 = 30.0;

/// The base scenes, one per engine.
const BASES: [&str; 3] = ["ellipsoids.toml", "soft.toml", "hard.toml"];

/// One step of a path to a number in a TOML document.
#[derive(Debug, Clone)]
enum Key {
    Field(String),
    Index(usize),
}

/// Every path to a number (a float or an integer, alone or in an array) of `value`, and to every array of numbers
/// (as a whole, for wrong lengths); `true` marks the arrays.
fn numeric_paths(value: &toml::Value, path: &mut Vec<Key>, out: &mut Vec<(Vec<Key>, bool)>) {
    match value {
        toml::Value::Float(_) | toml::Value::Integer(_) => out.push((path.clone(), false)),
        toml::Value::Array(items) => {
            if !items.is_empty() && items.iter().all(|v| v.is_float() || v.is_integer()) {
                out.push((path.clone(), true));
            }
            for (k, v) in items.iter().enumerate() {
                path.push(Key::Index(k));
                numeric_paths(v, path, out);
                path.pop();
            }
        }
        toml::Value::Table(t) => {
            for (k, v) in t {
                path.push(Key::Field(k.clone()));
                numeric_paths(v, path, out);
                path.pop();
            }
        }
        _ => {}
    }
}

fn get_mut<'a>(value: &'a mut toml::Value, path: &[Key]) -> &'a mut toml::Value {
    path.iter().fold(value, |v, k| match k {
        Key::Field(f) => &mut v[f.as_str()],
        Key::Index(i) => &mut v[*i],
    })
}

fn show(path: &[Key]) -> String {
    let mut s = String::new();
    for k in path {
        match k {
            Key::Field(f) if s.is_empty() => s.push_str(f),
            Key::Field(f) => s.push_str(&format!(".{f}")),
            Key::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

/// The values a number is mutated to (a selector picks one).
const EXTREMES: [f64; 10] = [
    1e308,
    -1e308,
    1e-320,
    -1e-320,
    0.0,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    -1.0,
    1e-300,
];

/// A mutation of one number or array of a base scene.
#[derive(Debug, Clone)]
struct Mutation {
    base: usize,
    target: prop::sample::Index,
    kind: u8,
    pick: prop::sample::Index,
}

fn mutation() -> impl Strategy<Value = Mutation> {
    (
        0..BASES.len(),
        any::<prop::sample::Index>(),
        0u8..16,
        any::<prop::sample::Index>(),
    )
        .prop_map(|(base, target, kind, pick)| Mutation {
            base,
            target,
            kind,
            pick,
        })
}

/// The mutated scene text and a description of the mutation.
fn mutate(m: &Mutation) -> (String, String) {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/bad_input");
    let text = std::fs::read_to_string(root.join(BASES[m.base])).unwrap();
    let mut doc: toml::Value = toml::Value::Table(text.parse::<toml::Table>().unwrap());
    let mut paths = Vec::new();
    numeric_paths(&doc, &mut Vec::new(), &mut paths);
    let (path, is_array) = m.target.get(&paths).clone();
    let slot = get_mut(&mut doc, &path);
    let what = match (is_array, slot.clone()) {
        (true, toml::Value::Array(mut items)) => {
            // Wrong lengths: one more number, one fewer, none.
            match m.kind % 3 {
                0 => items.push(toml::Value::Float(1.0)),
                1 => {
                    items.pop();
                }
                _ => items.clear(),
            }
            let n = items.len();
            *slot = toml::Value::Array(items);
            format!("{} with {n} numbers", show(&path))
        }
        (_, toml::Value::Integer(i)) => {
            let new = match m.kind % 4 {
                0 => toml::Value::Integer(0),
                1 => toml::Value::Integer(-1),
                2 => toml::Value::Integer(i64::MAX),
                _ => toml::Value::Float(*m.pick.get(&EXTREMES)),
            };
            let what = format!("{} = {new} (was {i})", show(&path));
            *slot = new;
            what
        }
        (_, old) => {
            let x = old.as_float().unwrap_or(1.0);
            let new = match m.kind {
                0..=9 => EXTREMES[m.kind as usize],
                10 => x * 1e10,
                11 => x * 1e-10,
                12 => -x,
                _ => *m.pick.get(&EXTREMES),
            };
            *slot = toml::Value::Float(new);
            format!("{} = {new:e} (was {old})", show(&path))
        }
    };
    (toml::to_string(&doc).unwrap(), what)
}

/// How one invocation ended.
struct Outcome {
    code: Option<i32>,
    stderr: String,
    seconds: f64,
}

/// Runs the binary in `dir` with `args`, killed after `limit_s` seconds (an error then).
fn invoke(dir: &Path, args: &[&str], limit_s: f64) -> Result<Outcome, String> {
    let err_path = dir.join("stderr.txt");
    let err_file = std::fs::File::create(&err_path).unwrap();
    let start = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_rubblepile"))
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(err_file)
        .spawn()
        .expect("start the binary");
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed().as_secs_f64() > limit_s {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!(
                "`rubblepile {}` did not end within {limit_s} s (killed)",
                args.join(" ")
            ));
        }
        std::thread::sleep(Duration::from_millis(2));
    };
    Ok(Outcome {
        code: status.code(),
        stderr: std::fs::read_to_string(&err_path).unwrap_or_default(),
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// What an invocation must look like: exit 0, or one `error: ` line with exit 2 (bad input, naming the scene
/// file) or exit 1 (a run that failed, naming its cause); no panic, no signal, nothing else on stderr.
fn judge(o: &Outcome, run: bool) -> Result<(), String> {
    let lines: Vec<&str> = o.stderr.lines().collect();
    let errors: Vec<&&str> = lines.iter().filter(|l| l.starts_with("error: ")).collect();
    let stray: Vec<&&str> = lines
        .iter()
        .filter(|l| !l.starts_with("error: ") && !l.starts_with("warning: "))
        .collect();
    match o.code {
        None => Err("killed by a signal".into()),
        _ if o.stderr.contains("panicked") => Err(format!("panicked: {}", o.stderr)),
        _ if !stray.is_empty() => Err(format!("stray stderr lines: {stray:?}")),
        Some(0) if errors.is_empty() => Ok(()),
        Some(2) if errors.len() == 1 && errors[0].starts_with("error: scene.toml: ") => Ok(()),
        Some(1) if run && errors.len() == 1 && errors[0].starts_with("error: run failed: ") => Ok(()),
        Some(c) => Err(format!("exit {c} with stderr {:?}", o.stderr)),
    }
}

#[derive(Default)]
struct Tally {
    cases: u32,
    checks: u32,
    runs: u32,
    refused: u32,
    warned: u32,
    run_failed: u32,
    slowest: f64,
}

#[test]
fn mutated_scenes_end_in_one_clear_error_or_a_short_run() {
    let started = Instant::now();
    let config = Config {
        cases: CASES,
        failure_persistence: None,
        max_shrink_iters: 16,
        ..Config::default()
    };
    let mut runner = TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    let tally = std::sync::Mutex::new(Tally::default());
    let result = runner.run(&mutation(), |m| {
        let (text, what) = mutate(&m);
        let dir = common::temp_dir(&format!("fuzz-{}", tally.lock().unwrap().cases));
        std::fs::write(dir.join("scene.toml"), &text).unwrap();
        let fail =
            |e: String| TestCaseError::fail(format!("{} ({what}): {e}\n--- scene.toml ---\n{text}", BASES[m.base]));
        let check = invoke(&dir, &["check", "scene.toml"], CHECK_LIMIT_S).map_err(fail)?;
        judge(&check, false).map_err(|e| fail(format!("check: {e}")))?;
        if std::env::var_os("SCENE_FUZZ_VERBOSE").is_some() {
            println!(
                "{} ({what}): {}",
                BASES[m.base],
                check.stderr.lines().next().unwrap_or("accepted")
            );
        }
        let mut t = tally.lock().unwrap();
        t.cases += 1;
        t.checks += 1;
        t.slowest = t.slowest.max(check.seconds);
        let warned = check
            .stderr
            .lines()
            .any(|l| l.starts_with("warning: ") && l.contains("more than 1e9"));
        if check.code == Some(0) && warned {
            t.warned += 1;
        } else if check.code == Some(0) {
            drop(t);
            let run = invoke(
                &dir,
                &["run", "scene.toml", "--out", "out", "--no-progress"],
                RUN_LIMIT_S,
            )
            .map_err(fail)?;
            judge(&run, true).map_err(|e| fail(format!("run: {e}")))?;
            let mut t = tally.lock().unwrap();
            t.runs += 1;
            t.run_failed += u32::from(run.code == Some(1));
            t.refused += u32::from(run.code == Some(2));
            t.slowest = t.slowest.max(run.seconds);
        } else {
            t.refused += 1;
        }
        let _ = std::fs::remove_dir_all(&dir);
        Ok(())
    });
    let t = tally.lock().unwrap();
    println!(
        "{} mutated scenes: {} checks, {} refused with one error, {} accepted with the work warning (not run), {} \
         accepted and run ({} of them failed with a named cause); slowest invocation {:.2} s; {:.1} s in all",
        t.cases,
        t.checks,
        t.refused,
        t.warned,
        t.runs,
        t.run_failed,
        t.slowest,
        started.elapsed().as_secs_f64()
    );
    if let Err(e) = result {
        panic!("{e}");
    }
    assert!(t.cases >= 500, "at least 500 mutated scenes, got {}", t.cases);
}

/// Scenes that crawl (a needle-thin ellipsoid, a spin of 1e10 rad/s, a hard-sphere step of 1e-9 s over 2 s) are
/// accepted, but `check` says so with a `warning:` naming the time scale and the step estimate, and `run` says it
/// before it starts (the run itself is killed here: it would not end in useful time).
#[test]
fn crawling_scenes_are_named_by_a_warning() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/bad_input");
    let cases = [
        (
            "ellipsoids.toml",
            "axes = [3.0, 2.0, 1.5]",
            "axes = [3.0, 3e-9, 3e-9]",
            "contact time of body[0]",
        ),
        (
            "ellipsoids.toml",
            "spin_body = [0.01, 0.02, 0.05]",
            "spin_body = [1e10, 0.0, 0.0]",
            "spin period of body[0]",
        ),
        (
            "hard.toml",
            "dt = 1e-3",
            "dt = 1e-9",
            "stepping.dt = 1e-9 s means 2.0e9 steps",
        ),
    ];
    for (k, (base, old, new, expect)) in cases.iter().enumerate() {
        let text = std::fs::read_to_string(root.join(base)).unwrap();
        assert!(text.contains(old), "{old:?} not in {base}");
        let dir = common::temp_dir(&format!("crawl-{k}"));
        std::fs::write(dir.join("scene.toml"), text.replacen(old, new, 1)).unwrap();
        let check = invoke(&dir, &["check", "scene.toml"], CHECK_LIMIT_S).unwrap();
        assert_eq!(check.code, Some(0), "{new}: {}", check.stderr);
        let warning = check.stderr.lines().find(|l| l.starts_with("warning: scene.toml: "));
        assert!(
            warning.is_some_and(|w| w.contains(expect) && w.contains("more than 1e9")),
            "{new}: no warning naming {expect:?}: {:?}",
            check.stderr
        );
        // The run prints the same warning before its first step; it is stopped after a second.
        let run = invoke(&dir, &["run", "scene.toml", "--out", "out", "--no-progress"], 1.0);
        let stderr = std::fs::read_to_string(dir.join("stderr.txt")).unwrap();
        assert!(
            stderr
                .lines()
                .next()
                .is_some_and(|l| l.starts_with("warning: ") && l.contains(expect)),
            "{new}: the run did not start with the warning: {stderr:?} ({:?})",
            run.map(|o| o.code)
        );
    }
}
