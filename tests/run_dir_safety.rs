//! Run directories that can be trusted (issue 53): nothing is written through a symbolic link planted where rubblepile
//! writes a file or a directory (every such path refused with one line naming it, the link's target untouched), and
//! the manifest of checksums finds a single flipped byte in any file of a finished run of each engine, and a damaged
//! or non-finite snapshot is refused by name by `resume`, `analyze`, `export` and `render`; a run directory written
//! before the manifest is checked row by row and said to have none. Every file is written below the test's own
//! temporary directory (links point into it too).

mod common;
use common::{describe, rubblepile, temp_dir};
use std::path::{Path, PathBuf};
use std::process::Output;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The bad-input corpus' base scene of an engine (`ellipsoids`, `soft`, `hard`) as `dir/<engine>.toml`, with
/// `replace` applied (each `[old, new]` once, `old` must be there).
fn scene(dir: &Path, engine: &str, replace: &[(&str, &str)]) -> PathBuf {
    let mut text = std::fs::read_to_string(root().join("tests/bad_input").join(format!("{engine}.toml"))).unwrap();
    for (old, new) in replace {
        assert!(text.contains(old), "{old:?} not in {engine}.toml");
        text = text.replacen(old, new, 1);
    }
    let p = dir.join(format!("{engine}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

/// The one `error: …` line of a failed command (asserting there is exactly one and no panic).
fn one_error(o: &Output, what: &str) -> String {
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && o.status.code().is_some(),
        "{what}: {}",
        describe(o)
    );
    assert!(!stderr.contains("panicked"), "{what}: {stderr}");
    let errors: Vec<&str> = stderr.lines().filter(|l| l.starts_with("error: ")).collect();
    assert_eq!(errors.len(), 1, "{what}: not one error line: {stderr}");
    errors[0].to_string()
}

/// A fresh target outside the run directory for a planted link: a file (or, `dir`, a directory holding one file)
/// whose content must survive the command.
fn target(base: &Path, name: &str, dir: bool) -> PathBuf {
    let t = base.join("outside").join(name);
    if dir {
        std::fs::create_dir_all(&t).unwrap();
        std::fs::write(t.join("kept.txt"), "precious").unwrap();
    } else {
        std::fs::create_dir_all(t.parent().unwrap()).unwrap();
        std::fs::write(&t, "precious").unwrap();
    }
    t
}

/// Whether the target of [`target`] is as it was (and a directory target got nothing new).
fn untouched(t: &Path) -> bool {
    if t.is_dir() {
        let names: Vec<_> = std::fs::read_dir(t).unwrap().map(|e| e.unwrap().file_name()).collect();
        names.len() == 1 && std::fs::read_to_string(t.join("kept.txt")).unwrap() == "precious"
    } else {
        std::fs::read_to_string(t).unwrap() == "precious"
    }
}

/// Plants a link at `run/rel` (replacing what is there) to a fresh target, runs `args` in `base`, and asserts the
/// command is refused with one line naming the link and that the target is untouched; removes the link after.
fn refused_through_link(base: &Path, run: &Path, rel: &str, dir_link: bool, args: &[&str]) {
    let link = run.join(rel);
    let what = format!("{rel} for {args:?}");
    let t = target(base, &rel.replace('/', "_"), dir_link);
    if link.is_dir() && !link.is_symlink() {
        std::fs::remove_dir_all(&link).unwrap();
    } else if link.symlink_metadata().is_ok() {
        std::fs::remove_file(&link).unwrap();
    }
    std::os::unix::fs::symlink(&t, &link).unwrap();
    let o = rubblepile(base, args);
    let e = one_error(&o, &what);
    assert!(e.contains("symbolic link"), "{what}: {e}");
    assert!(e.contains(rel), "{what}: the link is not named: {e}");
    assert!(untouched(&t), "{what}: the link's target was written");
    std::fs::remove_file(&link).unwrap();
}

/// Runs `engine`'s base scene (with `replace`) into `base/<name>`, with `extra` arguments and checkpoints every
/// quarter or so of its simulated time; returns the directory and what the command did.
fn run_into(base: &Path, engine: &str, replace: &[(&str, &str)], name: &str, extra: &[&str]) -> (PathBuf, Output) {
    let sc = scene(base, engine, replace);
    let out = base.join(name);
    let every = match engine {
        "soft" => "0.004",
        "hard" => "0.5",
        _ => "25",
    };
    let mut args = vec![
        "run",
        s(&sc),
        "--out",
        s(&out),
        "--no-progress",
        "--checkpoint-every-sim-s",
        every,
    ];
    args.extend(extra);
    let o = rubblepile(base, &args);
    (out, o)
}

/// A finished run of `engine`'s base scene in `base/<name>` with a checkpoint, extra snapshot formats `formats`.
fn finished(base: &Path, engine: &str, replace: &[(&str, &str)], name: &str, formats: &[&str]) -> PathBuf {
    let extra: Vec<&str> = formats.iter().flat_map(|f| ["--format", f]).collect();
    let (out, o) = run_into(base, engine, replace, name, &extra);
    assert!(o.status.success(), "{engine}: {}", describe(&o));
    out
}

/// The ellipsoid run stopped right after its first checkpoint (t = 25 s of 60; snapshots 0 and 1 written).
fn stopped(base: &Path, name: &str) -> PathBuf {
    let track = [("every = 1.0", "every = 1.0\ntrack = [0]")];
    let (out, o) = run_into(base, "ellipsoids", &track, name, &["--stop-after-checkpoints", "1"]);
    assert_eq!(o.status.code(), Some(3), "{}", describe(&o));
    out
}

#[cfg(unix)]
#[test]
fn a_symlink_where_rubblepile_writes_is_refused_by_name_and_its_target_untouched() {
    let base = temp_dir("links");
    let sc = scene(&base, "ellipsoids", &[("every = 1.0", "every = 1.0\ntrack = [0]")]);
    let run = finished(
        &base,
        "ellipsoids",
        &[("every = 1.0", "every = 1.0\ntrack = [0]")],
        "run",
        &[],
    );
    let again = ["run", s(&sc), "--out", s(&run), "--no-progress", "--force"];
    let stop = stopped(&base, "stopped");
    let resume = ["resume", s(&stop), "--no-progress"];
    // `run --force` over a previous run: the lock, every file it writes or removes, its snapshots (the directory and
    // a file in it); `resume`: the lock, the files it reopens, rewrites or removes, a snapshot it will write.
    let cases: [(&Path, &[&str], &[&str]); 2] = [
        (
            &run,
            &again,
            &[
                ".rubblepile.lock",
                "scene.toml",
                "summary.json",
                "timeseries.csv",
                "tracks.csv",
                "checkpoint.json",
                "manifest.txt",
                "snapshots/1.csv",
            ],
        ),
        (
            &stop,
            &resume,
            &[
                ".rubblepile.lock",
                "timeseries.csv",
                "tracks.csv",
                "summary.json",
                "checkpoint.json",
                "snapshots/3.csv",
            ],
        ),
    ];
    for (dir, args, files) in cases {
        for rel in files {
            refused_through_link(&base, dir, rel, false, args);
        }
        refused_through_link(&base, dir, "snapshots", true, args);
    }
    let o = rubblepile(&base, &again);
    assert!(o.status.success(), "after the links: {}", describe(&o));

    // `analyze` (its lock, analysis/ and a file in it), `render` (its lock, frames/ and a frame), `export` (vtk/,
    // a VTK file, an XYZ file).
    let analyze = ["analyze", s(&run), "--force"];
    refused_through_link(&base, &run, ".rubblepile-analysis.lock", false, &analyze);
    refused_through_link(&base, &run, "analysis", true, &analyze);
    std::fs::create_dir_all(run.join("analysis")).unwrap();
    refused_through_link(&base, &run, "analysis/analysis.json", false, &analyze);
    refused_through_link(&base, &run, "analysis/clumps.csv", false, &analyze);
    let render = ["render", s(&run), "--force", "--size", "64x64"];
    refused_through_link(&base, &run, ".rubblepile-frames.lock", false, &render);
    refused_through_link(&base, &run, "frames", true, &render);
    std::fs::create_dir_all(run.join("frames")).unwrap();
    refused_through_link(&base, &run, "frames/0000.png", false, &render);
    refused_through_link(&base, &run, "frames/run.gif", false, &render);
    let vtk = ["export", "vtk", s(&run), "--force"];
    refused_through_link(&base, &run, "vtk", true, &vtk);
    std::fs::create_dir_all(run.join("vtk")).unwrap();
    refused_through_link(&base, &run, "vtk/run.pvd", false, &vtk);
    refused_through_link(
        &base,
        &run,
        "snapshots/0.xyz",
        false,
        &["export", "xyz", s(&run), "--force"],
    );
    for args in [&analyze[..], &render[..], &vtk[..]] {
        let o = rubblepile(&base, args);
        assert!(o.status.success(), "{args:?} after the links: {}", describe(&o));
    }
}

#[cfg(unix)]
#[test]
fn campaign_indexes_and_job_scripts_are_not_written_through_links() {
    let base = temp_dir("links-campaign");
    std::fs::write(
        base.join("c.toml"),
        format!(
            "[campaign]\nout = \"camp\"\ntargets = [\"{}\"]\nprojectiles = [\"P2\"]\nangles = [45.0]\nseeds = [1]\n\
             [impact]\nt_end = 20.0\nevery = 10.0\n",
            root().join("targets/N30_T4.csv").display()
        ),
    )
    .unwrap();
    let camp = base.join("camp");
    std::fs::create_dir_all(&camp).unwrap();
    let slurm = ["campaign", "slurm", "c.toml", "--tasks", "2"];
    refused_through_link(&base, &camp, "campaign.slurm", false, &slurm);
    let o = rubblepile(&base, &["campaign", "c.toml", "--no-progress"]);
    assert!(o.status.success(), "{}", describe(&o));
    let merge = ["campaign", "merge", "camp"];
    refused_through_link(&base, &camp, "campaign.csv", false, &merge);
    refused_through_link(&base, &camp, ".rubblepile.lock", false, &merge);
    let o = rubblepile(&base, &merge);
    assert!(o.status.success(), "{}", describe(&o));
}

/// Flips one bit of the byte in the middle of `path`.
fn flip(path: &Path) {
    let mut b = std::fs::read(path).unwrap();
    let i = b.len() / 2;
    b[i] ^= 0x04;
    std::fs::write(path, b).unwrap();
}

#[test]
fn check_finds_a_single_flipped_byte_in_any_file_of_a_finished_run_of_each_engine() {
    let base = temp_dir("flip");
    let track = [("every = 1.0", "every = 1.0\ntrack = [0, 1]")];
    let runs = [
        finished(&base, "ellipsoids", &track, "ellipsoids", &["xyz"]),
        finished(&base, "soft", &[], "soft", &["vtk"]),
        finished(&base, "hard", &[], "hard", &[]),
    ];
    let mut flipped = 0;
    for run in &runs {
        let o = rubblepile(&base, &["check", s(run)]);
        assert!(o.status.success(), "{}", describe(&o));
        assert!(
            String::from_utf8_lossy(&o.stdout).contains("manifest: the "),
            "{}",
            describe(&o)
        );
        // Every file but the lock files (the pid of the last writer, no record of the run).
        let files: Vec<String> = common::files_below(run)
            .iter()
            .map(|p| p.display().to_string())
            .collect();
        for must in [
            "checkpoint.json",
            "summary.json",
            "timeseries.csv",
            "scene.toml",
            "manifest.txt",
        ] {
            assert!(files.iter().any(|f| f == must), "{}: no {must}", run.display());
        }
        for rel in &files {
            let p = run.join(rel);
            let before = std::fs::read(&p).unwrap();
            flip(&p);
            let o = rubblepile(&base, &["check", s(run)]);
            let e = one_error(&o, &format!("{rel} flipped"));
            assert_eq!(o.status.code(), Some(2), "{rel}: {}", describe(&o));
            let named = if rel == "manifest.txt" {
                "damaged manifest".to_string()
            } else {
                format!("{rel}: damaged")
            };
            assert!(
                e.contains("is not whole") && e.contains(&named),
                "{}: a flipped byte in {rel} is not named first: {e}",
                run.display()
            );
            std::fs::write(&p, before).unwrap();
            flipped += 1;
        }
        let o = rubblepile(&base, &["check", s(run)]);
        assert!(o.status.success(), "restored: {}", describe(&o));
    }
    assert!(flipped >= 30, "only {flipped} files flipped");
}

#[test]
fn readers_refuse_a_damaged_or_non_finite_snapshot_with_one_line() {
    let base = temp_dir("damaged-readers");
    let run = finished(&base, "ellipsoids", &[], "run", &[]);
    let snap = run.join("snapshots/3.csv");
    let good = std::fs::read(&snap).unwrap();
    // Cut 7 bytes short, mid-number: with the manifest, and without it (a run written before the manifest).
    std::fs::write(&snap, &good[..good.len() - 7]).unwrap();
    let analyze = ["analyze", s(&run), "--force"];
    let export = ["export", "xyz", s(&run), "--force"];
    let render = ["render", s(&run), "--force", "--size", "64x64"];
    for args in [&analyze[..], &export[..], &render[..]] {
        let e = one_error(&rubblepile(&base, args), &format!("{args:?}"));
        assert!(
            e.contains(&format!("{}: damaged: ", snap.display())) && e.contains("(cut short)"),
            "{args:?}: {e}"
        );
    }
    std::fs::remove_file(run.join("manifest.txt")).unwrap();
    let o = rubblepile(&base, &["check", s(&run)]);
    let e = one_error(&o, "check without a manifest");
    assert!(e.contains("cut short mid-row"), "{e}");
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("no manifest ("),
        "{}",
        describe(&o)
    );
    for args in [&analyze[..], &export[..], &render[..]] {
        let e = one_error(&rubblepile(&base, args), &format!("{args:?} without a manifest"));
        assert!(
            e.contains("3.csv: damaged: its last line ends without a newline"),
            "{args:?}: {e}"
        );
    }
    // A NaN in the last snapshot: named, never skipped for another one.
    let text = String::from_utf8(good.clone()).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let cells: Vec<&str> = lines[1].split(',').collect();
    lines[1] = std::iter::once("NaN")
        .chain(cells[1..].iter().copied())
        .collect::<Vec<_>>()
        .join(",");
    std::fs::write(&snap, lines.join("\n") + "\n").unwrap();
    for args in [&analyze[..], &export[..], &render[..]] {
        let e = one_error(&rubblepile(&base, args), &format!("{args:?} NaN"));
        assert!(e.contains("column t: \"NaN\" is not a finite number"), "{args:?}: {e}");
    }
    std::fs::write(&snap, &good).unwrap();
    let o = rubblepile(&base, &["check", s(&run)]);
    assert!(o.status.success(), "{}", describe(&o));

    // resume: a snapshot written before the checkpoint, damaged.
    let stop = stopped(&base, "stopped");
    flip(&stop.join("snapshots/1.csv"));
    let e = one_error(&rubblepile(&base, &["resume", s(&stop), "--no-progress"]), "resume");
    assert!(
        e.contains("cannot resume") && e.contains("snapshots/1.csv: damaged"),
        "{e}"
    );
}

/// Issue 57: `run --force` (and `impact --force`, through the same preparation) over a previous run removes that
/// run's derived `analysis/` and `frames/` too: nothing left describes the old snapshots, and `analyze` of the new
/// run is not refused for an existing analysis.
#[test]
fn force_leaves_no_stale_analysis_or_frames() {
    let base = temp_dir("force-derived");
    let sc = scene(&base, "ellipsoids", &[]);
    let run = finished(&base, "ellipsoids", &[], "run", &[]);
    let a = rubblepile(&base, &["analyze", s(&run)]);
    assert!(a.status.success(), "{}", describe(&a));
    assert!(run.join("analysis").is_dir());
    std::fs::create_dir_all(run.join("frames")).unwrap();
    std::fs::write(run.join("frames/0000.png"), b"old").unwrap();
    let again = rubblepile(&base, &["run", s(&sc), "--out", s(&run), "--no-progress", "--force"]);
    assert!(again.status.success(), "{}", describe(&again));
    assert!(!run.join("analysis").exists(), "stale analysis/ kept");
    assert!(!run.join("frames").exists(), "stale frames/ kept");
    let a = rubblepile(&base, &["analyze", s(&run)]);
    assert!(a.status.success(), "{}", describe(&a));
}
