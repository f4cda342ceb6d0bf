//! The bad-input corpus (`tests/bad_input/cases.toml`): malformed scenes of the three engines, bodies and particles
//! files, campaign files, aggregate and spin-up options, and damaged checkpoints, each run through the binary. Every
//! case must end with a non-zero exit code (not a signal), a one-line `error: …` naming what it expects, no panic,
//! and no output directory that a later run would take for a finished one. `files` may name files in folders (the
//! folders are created); `env` sets environment variables of the command; `links` plants symbolic links (the link,
//! `OUT` for the output directory, to a target in the case directory that the harness creates holding `precious`
//! and checks is untouched after the command: nothing may be written through a link).

mod common;
use common::temp_dir;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

#[derive(Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Corpus {
    case: Vec<Case>,
}

#[derive(Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Case {
    name: String,
    kind: String,
    expect: String,
    base: Option<String>,
    replace: Option<[String; 2]>,
    args: Option<Vec<String>>,
    prepare: Option<String>,
    damage: Option<Damage>,
    #[serde(default)]
    files: BTreeMap<String, String>,
    #[serde(default)]
    env: BTreeMap<String, String>,
    #[serde(default)]
    links: BTreeMap<String, String>,
}

#[derive(Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Damage {
    op: String,
    from: Option<String>,
    to: Option<String>,
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn rubblepile(cwd: &Path, args: &[String]) -> std::process::Output {
    rubblepile_with(cwd, args, &BTreeMap::new())
}

fn rubblepile_with(cwd: &Path, args: &[String], env: &BTreeMap<String, String>) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_rubblepile"))
        .args(args)
        .envs(env)
        .current_dir(cwd)
        .output()
        .expect("run the binary")
}

/// The link of a `links` entry (`OUT` is the output directory) and its target, in the case directory `dir`.
fn link_paths(dir: &Path, out: &Path, link: &str, target: &str) -> (PathBuf, PathBuf) {
    let link = link.replace("OUT", &out.display().to_string());
    (dir.join(link), dir.join(target))
}

/// Whether `out` holds a run that claims to have completed.
fn looks_finished(out: &Path) -> bool {
    std::fs::read_to_string(out.join("summary.json")).is_ok_and(|t| t.contains("\"status\": \"completed\""))
}

/// The lock a `hold-lock` damage holds while its case runs.
static HELD: std::sync::Mutex<Option<rubblepile::io::run_lock::DirLock>> = std::sync::Mutex::new(None);

/// Sets the case up in `dir`; returns an error text for a broken case (a replacement that matches nothing).
fn prepare(case: &Case, dir: &Path, out: &Path) -> Result<(), String> {
    let root_s = root().display().to_string();
    if let Some(base) = &case.base {
        let mut text = std::fs::read_to_string(root().join("tests/bad_input").join(base)).map_err(|e| e.to_string())?;
        if case.prepare.is_none()
            && let Some([old, new]) = &case.replace
        {
            if !text.contains(old.as_str()) {
                return Err(format!("replace: {old:?} is not in {base}"));
            }
            text = text.replacen(old.as_str(), new, 1);
        }
        std::fs::write(dir.join("scene.toml"), text.replace("ROOT", &root_s)).map_err(|e| e.to_string())?;
    }
    for (name, text) in &case.files {
        // A name may hold folders (e.g. `run/snapshots/0.csv` for a damaged run directory).
        let path = dir.join(name);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|e| e.to_string())?;
        }
        std::fs::write(path, text.replace("ROOT", &root_s)).map_err(|e| e.to_string())?;
    }
    if case.prepare.as_deref() == Some("checkpoint") {
        let out_s = out.display().to_string();
        let args: Vec<String> = [
            "run",
            "scene.toml",
            "--out",
            &out_s,
            "--no-progress",
            "--checkpoint-every-sim-s",
            "0",
            "--stop-after-checkpoints",
            "1",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        let o = rubblepile(dir, &args);
        if o.status.code() != Some(3) {
            return Err(format!(
                "preparing the checkpoint: exit {:?}: {}",
                o.status.code(),
                String::from_utf8_lossy(&o.stderr)
            ));
        }
        let ckpt = out.join("checkpoint.json");
        let none = Damage {
            op: "none".into(),
            from: None,
            to: None,
        };
        let damage = match (&case.damage, case.links.is_empty()) {
            (Some(d), _) => d,
            (None, false) => &none,
            (None, true) => return Err("prepare = \"checkpoint\" needs a damage (or links)".into()),
        };
        // A damaged file is found by the run's manifest first (issue 53); the damages below stand for run
        // directories written before it, whose files are checked on their own (`flip-snapshot` keeps it).
        if !matches!(damage.op.as_str(), "flip-snapshot" | "none") {
            std::fs::remove_file(out.join("manifest.txt")).map_err(|e| e.to_string())?;
        }
        match damage.op.as_str() {
            "truncate" => {
                let b = std::fs::read(&ckpt).map_err(|e| e.to_string())?;
                std::fs::write(&ckpt, &b[..b.len() / 2]).map_err(|e| e.to_string())?;
            }
            "delete" => std::fs::remove_file(&ckpt).map_err(|e| e.to_string())?,
            "replace" => {
                let (from, to) = (damage.from.as_deref().unwrap_or(""), damage.to.as_deref().unwrap_or(""));
                let t = std::fs::read_to_string(&ckpt).map_err(|e| e.to_string())?;
                if !t.contains(from) {
                    return Err(format!("damage: {from:?} is not in the checkpoint"));
                }
                std::fs::write(&ckpt, t.replacen(from, to, 1)).map_err(|e| e.to_string())?;
            }
            "edit-scene" => {
                let p = out.join("scene.toml");
                let t = std::fs::read_to_string(&p).map_err(|e| e.to_string())?;
                std::fs::write(&p, t + "\n# edited\n").map_err(|e| e.to_string())?;
            }
            "truncate-timeseries" => {
                std::fs::write(out.join("timeseries.csv"), "t\n").map_err(|e| e.to_string())?;
            }
            "delete-snapshots" => std::fs::remove_dir_all(out.join("snapshots")).map_err(|e| e.to_string())?,
            "none" => {}
            // Snapshot 0 cut 7 bytes short, mid-number (a run directory without a manifest).
            "cut-snapshot" => {
                let p = out.join("snapshots").join("0.csv");
                let b = std::fs::read(&p).map_err(|e| e.to_string())?;
                std::fs::write(&p, &b[..b.len() - 7]).map_err(|e| e.to_string())?;
            }
            // The first number of snapshot 0's last row made NaN (a run directory without a manifest).
            "nan-snapshot" => {
                let p = out.join("snapshots").join("0.csv");
                let t = std::fs::read_to_string(&p).map_err(|e| e.to_string())?;
                let mut lines: Vec<String> = t.lines().map(str::to_string).collect();
                let last = lines.last_mut().ok_or("empty snapshot")?;
                let rest = last.split_once(',').map_or(String::new(), |(_, r)| r.to_string());
                *last = format!("NaN,{rest}");
                std::fs::write(&p, lines.join("\n") + "\n").map_err(|e| e.to_string())?;
            }
            // One bit of snapshot 0 flipped, the manifest kept: the manifest names it.
            "flip-snapshot" => {
                let p = out.join("snapshots").join("0.csv");
                let mut b = std::fs::read(&p).map_err(|e| e.to_string())?;
                let i = b.len() / 2;
                b[i] ^= 0x04;
                std::fs::write(&p, b).map_err(|e| e.to_string())?;
            }
            // Another writer: this process holds the directory's lock until the case has run.
            "hold-lock" => {
                let lock = rubblepile::io::run_lock::DirLock::acquire(out).map_err(|e| e.to_string())?;
                *HELD.lock().unwrap() = Some(lock);
            }
            other => return Err(format!("unknown damage {other:?}")),
        }
    }
    for (link, target) in &case.links {
        let (link, target) = link_paths(dir, out, link, target);
        if let Some(parent) = target.parent() {
            std::fs::create_dir_all(parent).map_err(|e| e.to_string())?;
        }
        std::fs::write(&target, "precious").map_err(|e| e.to_string())?;
        if link.is_dir() && !link.is_symlink() {
            std::fs::remove_dir_all(&link).map_err(|e| e.to_string())?;
        } else if link.symlink_metadata().is_ok() {
            std::fs::remove_file(&link).map_err(|e| e.to_string())?;
        }
        if let Some(parent) = link.parent() {
            std::fs::create_dir_all(parent).map_err(|e| e.to_string())?;
        }
        std::os::unix::fs::symlink(&target, &link).map_err(|e| e.to_string())?;
    }
    Ok(())
}

#[test]
fn every_bad_input_gets_one_clear_error() {
    let text = std::fs::read_to_string(root().join("tests/bad_input/cases.toml")).unwrap();
    let corpus: Corpus = toml::from_str(&text).unwrap();
    let mut failures = Vec::new();
    let mut per_kind: BTreeMap<&str, usize> = BTreeMap::new();
    for case in &corpus.case {
        *per_kind.entry(case.kind.as_str()).or_default() += 1;
        let dir = temp_dir(&format!("bad-{}", case.name));
        let out = dir.join("out");
        if let Err(e) = prepare(case, &dir, &out) {
            failures.push(format!("{}: broken case: {e}", case.name));
            continue;
        }
        let out_s = out.display().to_string();
        let default_args = vec!["check".to_string(), "SCENE".to_string()];
        let args: Vec<String> = case
            .args
            .as_ref()
            .unwrap_or(&default_args)
            .iter()
            .map(|a| {
                a.replace("SCENE", "scene.toml")
                    .replace("OUT", &out_s)
                    .replace("ROOT", &root().display().to_string())
            })
            .collect();
        let o = rubblepile_with(&dir, &args, &case.env);
        HELD.lock().unwrap().take();
        let written_through = case.links.iter().find_map(|(link, target)| {
            let (_, target) = link_paths(&dir, &out, link, target);
            (std::fs::read_to_string(&target).ok().as_deref() != Some("precious")).then(|| target.display().to_string())
        });
        let stderr = String::from_utf8_lossy(&o.stderr);
        let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error: ")).collect();
        let problem = if o.status.code().is_none() {
            Some("killed by a signal".to_string())
        } else if o.status.success() {
            Some("accepted (exit 0)".to_string())
        } else if stderr.contains("panicked") {
            Some(format!("panicked: {stderr}"))
        } else if errors.len() != 1 {
            Some(format!("expected one `error: ` line, got: {stderr:?}"))
        } else if !errors[0].contains(case.expect.as_str()) {
            Some(format!("error does not name {:?}: {}", case.expect, errors[0]))
        } else if looks_finished(&out) {
            Some("left an output directory that looks finished".to_string())
        } else {
            written_through.map(|target| format!("wrote through a link into {target}"))
        };
        if let Some(p) = problem {
            failures.push(format!("{} ({}): {p}", case.name, case.kind));
        }
    }
    let counts: Vec<String> = per_kind.iter().map(|(k, n)| format!("{k}: {n}")).collect();
    println!("{} cases ({})", corpus.case.len(), counts.join(", "));
    assert!(corpus.case.len() >= 130, "the corpus must hold at least 130 cases");
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        corpus.case.len(),
        failures.join("\n")
    );
}
