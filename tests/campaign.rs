//! Impact campaigns (`rubblepile campaign`): a small grid runs and is listed in `campaign.csv`; a second
//! invocation skips every completed run without touching it; a run stopped after its first checkpoint is
//! resumed (not restarted) and ends bit for bit like an uninterrupted run; bad campaign files give one-line
//! errors naming the field; `rubblepile impact` still works as a thin wrapper of the library.
//!
//! Everything runs on a tiny target (6 fragments, 3 → 1.5 km) built here, hit by 1 km projectiles at a few
//! tens of m/s, for a few tens of simulated seconds.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::SystemTime;

use rubblepile::driver::RunOptions;
use rubblepile::ellipsoid::body::InertiaModel;
use rubblepile::ellipsoid::output::write_snapshot;
use rubblepile::impact::campaign::{
    Action, CAMPAIGN_COLUMNS, CampaignOptions, RunStatus, Shard, load_campaign, merge_campaign, parse_campaign,
    run_campaign,
};
use rubblepile::impact::run::run_impact;
use rubblepile::impact::target::build_target;
use rubblepile::integrate::Method;

fn temp_dir(tag: &str) -> PathBuf {
    static N: AtomicUsize = AtomicUsize::new(0);
    let n = N.fetch_add(1, Ordering::SeqCst);
    let nanos = SystemTime::now()
        .duration_since(SystemTime::UNIX_EPOCH)
        .map(|d| d.subsec_nanos())
        .unwrap_or(0);
    let dir = std::env::temp_dir().join(format!("rubblepile-campaign-{tag}-{}-{n}-{nanos}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The tiny target's CSV text, built once per test process (6 fragments, 3 → 1.5 km, 6 h period).
fn tiny_target_csv() -> &'static [u8] {
    static CSV: OnceLock<Vec<u8>> = OnceLock::new();
    CSV.get_or_init(|| {
        let mut spec = common::small_pile_spec(1, 6, 3e3, 1.5e3, 0.1);
        spec.f0 = 1e-3; // damps this small pile to rigid rotation quickly
        let mut quiet = |_: usize, _: f64, _: f64, _: f64| {};
        let (bodies, _) = build_target(&spec, &mut quiet).unwrap();
        let dir = temp_dir("target");
        let path = dir.join("tiny.csv");
        write_snapshot(&path, 0.0, &bodies).unwrap();
        let text = std::fs::read(&path).unwrap();
        let _ = std::fs::remove_dir_all(&dir);
        text
    })
}

/// A campaign directory `dir` with `targets/tiny.csv` and `campaign.toml` (`[campaign]` lines given).
fn campaign_dir(tag: &str, campaign: &str) -> (PathBuf, PathBuf) {
    let dir = temp_dir(tag);
    std::fs::create_dir_all(dir.join("targets")).unwrap();
    std::fs::write(dir.join("targets/tiny.csv"), tiny_target_csv()).unwrap();
    let file = dir.join("campaign.toml");
    std::fs::write(&file, campaign).unwrap();
    (dir, file)
}

/// A 2 × 2 grid: projectiles S1 (1 km) and S2 (0.8 km) at 20 m/s, ζ = 0 and 90°, to t = 40 s.
const GRID: &str = r#"
[campaign]
out = "out"
targets = ["targets/tiny.csv"]
projectiles = ["S1", "S2"]
angles = [0, 90.0]
seeds = [7]
parallel = 2

[impact]
t_end = 40.0
contact_time = 5.0
every = 5.0
rtol = 1e-8

[[projectile]]
id = "S1"
radius_km = 1.0
speed_km_s = 0.02

[[projectile]]
id = "S2"
radius_km = 0.8
speed_km_s = 0.02
"#;

fn quiet() -> CampaignOptions {
    CampaignOptions {
        run: RunOptions {
            progress: false,
            ..RunOptions::default()
        },
        parallel: None,
        threads_per_run: None,
        verbose: false,
        shard: None,
    }
}

fn read_csv(path: &Path) -> Vec<Vec<String>> {
    let mut r = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = r.headers().unwrap().iter().map(String::from).collect();
    assert_eq!(header, CAMPAIGN_COLUMNS);
    r.records()
        .map(|x| x.unwrap().iter().map(String::from).collect())
        .collect()
}

/// Every file under `dir` with its bytes and modification time, lock files aside (they name the last writer's pid and
/// are rewritten by every writer, a campaign that skips everything included).
fn tree(dir: &Path) -> Vec<(PathBuf, Vec<u8>, SystemTime)> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.file_name().is_some_and(rubblepile::io::run_lock::is_lock_file) {
            continue;
        }
        if p.is_dir() {
            out.extend(tree(&p));
        } else {
            let modified = std::fs::metadata(&p).unwrap().modified().unwrap();
            out.push((p.clone(), std::fs::read(&p).unwrap(), modified));
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

fn bin(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rubblepile"))
        .args(args)
        .output()
        .expect("run rubblepile")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// (a) the grid runs, `campaign.csv` lists every run completed with finite errors; (b) a second invocation
/// skips every run and modifies nothing in the run directories; a run directory whose scene no longer matches
/// the campaign is left alone and recorded as failed while the rest is skipped.
#[test]
fn grid_runs_then_everything_is_skipped() {
    let (dir, file) = campaign_dir("grid", GRID);
    let campaign = load_campaign(&file).unwrap();
    assert_eq!(campaign.points.len(), 4);
    let names: Vec<&str> = campaign.points.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        names,
        ["tiny_S1_z0_s7", "tiny_S1_z90_s7", "tiny_S2_z0_s7", "tiny_S2_z90_s7"]
    );
    assert_eq!(campaign.out, dir.join("out"));
    assert_eq!(campaign.parallel, 2);

    let report = run_campaign(&campaign, &quiet()).unwrap();
    assert_eq!(report.completed(), 4, "{}", report.one_line());
    assert!(report.runs.iter().all(|r| r.action == Action::Start));
    let worst = report.worst_energy_error().unwrap().0;
    assert!(worst.is_finite() && worst < 1e-5, "{}", report.one_line());

    let rows = read_csv(&dir.join("out/campaign.csv"));
    assert_eq!(rows.len(), 4);
    for (row, name) in rows.iter().zip(&names) {
        assert_eq!(row[0], *name);
        assert_eq!(row[1], "tiny");
        assert_eq!(row[4], "7");
        assert_eq!(row[6], "completed", "{row:?}");
        assert_eq!(row[8].parse::<f64>().unwrap(), 40.0);
        assert!(row[5].parse::<f64>().unwrap() > 0.0, "Q {row:?}");
        for k in 11..14 {
            let e: f64 = row[k].parse().unwrap();
            assert!(e.is_finite() && e >= 0.0, "{} = {e} in {row:?}", CAMPAIGN_COLUMNS[k]);
        }
        let summary = std::fs::read_to_string(dir.join("out").join(name).join("summary.json")).unwrap();
        assert!(summary.contains("\"status\": \"completed\""));
    }
    assert_eq!(rows[1][2], "S1");
    assert_eq!(rows[1][3], "90");
    assert!(!dir.join("out/campaign.csv.tmp").exists());

    // (b) again: everything skipped, nothing in the run directories touched.
    let before = tree(&dir.join("out"));
    let again = run_campaign(&load_campaign(&file).unwrap(), &quiet()).unwrap();
    assert_eq!(again.skipped(), 4, "{}", again.one_line());
    assert_eq!(again.completed(), 4);
    let after = tree(&dir.join("out"));
    let runs_only = |t: &[(PathBuf, Vec<u8>, SystemTime)]| -> Vec<(PathBuf, Vec<u8>, SystemTime)> {
        t.iter()
            .filter(|(p, _, _)| !p.ends_with("campaign.csv"))
            .cloned()
            .collect()
    };
    assert_eq!(runs_only(&before), runs_only(&after));
    assert_eq!(read_csv(&dir.join("out/campaign.csv")), rows);

    // A completed run whose scene differs from the campaign's: left alone, recorded as failed.
    let changed = GRID.replace("t_end = 40.0", "t_end = 40.0\nf0 = 2e-4");
    std::fs::write(&file, changed).unwrap();
    let conflict = run_campaign(&load_campaign(&file).unwrap(), &quiet()).unwrap();
    assert_eq!(conflict.failed(), 4, "{}", conflict.one_line());
    assert!(matches!(&conflict.runs[0].status, RunStatus::Failed(c) if c.contains("scene.toml differs")));
    assert_eq!(runs_only(&tree(&dir.join("out"))), runs_only(&before));
    let rows = read_csv(&dir.join("out/campaign.csv"));
    assert!(rows[0][6].starts_with("failed: "), "{:?}", rows[0]);
    // the campaign as it was: a run whose scene.toml holds the same values in another layout (as older builds
    // wrote it) is still this run, skipped
    std::fs::write(&file, GRID).unwrap();
    let scene = dir.join("out/tiny_S1_z0_s7/scene.toml");
    let table: toml::Table = std::fs::read_to_string(&scene).unwrap().parse().unwrap();
    std::fs::write(
        &scene,
        format!("# another layout\n{}", toml::to_string(&table).unwrap()),
    )
    .unwrap();
    let relaid = run_campaign(&load_campaign(&file).unwrap(), &quiet()).unwrap();
    assert_eq!(relaid.skipped(), 4, "{}", relaid.one_line());
    let _ = std::fs::remove_dir_all(&dir);
}

/// (c) runs stopped right after their first checkpoint (the hidden `--stop-after-checkpoints`, through the
/// binary: exit code 3) are resumed by the next invocation, not restarted, and end bit for bit like an
/// uninterrupted run of the same grid point.
#[test]
fn stopped_runs_are_resumed_bit_for_bit() {
    let grid = GRID
        .replace("projectiles = [\"S1\", \"S2\"]", "projectiles = [\"S1\"]")
        .replace("angles = [0, 90.0]", "angles = [45.0]");
    let (dir, file) = campaign_dir("resume", &grid);
    let f = file.to_str().unwrap();
    let out = bin(&[
        "campaign",
        f,
        "--checkpoint-every-sim-s",
        "10",
        "--stop-after-checkpoints",
        "1",
    ]);
    assert_eq!(out.status.code(), Some(3), "{}", stderr(&out));
    let run = dir.join("out/tiny_S1_z45_s7");
    assert!(run.join("checkpoint.json").is_file());
    assert!(!run.join("summary.json").exists());
    let rows = read_csv(&dir.join("out/campaign.csv"));
    assert_eq!(rows[0][6], "pending");
    let initial = tree(&run)
        .into_iter()
        .filter(|(p, _, _)| p.ends_with("initial_bodies.csv") || p.ends_with("impact.json"))
        .collect::<Vec<_>>();
    assert_eq!(initial.len(), 2);

    let out = bin(&["campaign", f, "--no-progress"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("1 completed (0 skipped, 1 resumed)"), "{stdout}");
    // not restarted: the set-up files are those of the first invocation
    for (p, bytes, modified) in &initial {
        assert_eq!(&std::fs::read(p).unwrap(), bytes);
        assert_eq!(std::fs::metadata(p).unwrap().modified().unwrap(), *modified);
    }
    assert_eq!(read_csv(&dir.join("out/campaign.csv"))[0][6], "completed");

    // The same grid point, uninterrupted.
    let campaign = load_campaign(&file).unwrap();
    let whole = dir.join("whole");
    let options = RunOptions {
        progress: false,
        ..RunOptions::default()
    };
    let summary = run_impact(&campaign.points[0].config, &whole, &options).unwrap();
    assert!(summary.completed());
    let snapshots = |d: &Path| -> Vec<(PathBuf, Vec<u8>)> {
        tree(&d.join("snapshots"))
            .into_iter()
            .map(|(p, bytes, _)| (p.strip_prefix(d).unwrap().to_path_buf(), bytes))
            .collect()
    };
    assert_eq!(snapshots(&run).len(), 2); // t = 0 and t_end = 40 s
    assert_eq!(snapshots(&run), snapshots(&whole), "snapshots differ");
    let json = |d: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(d.join("summary.json")).unwrap()).unwrap()
    };
    let (a, b) = (json(&run), json(&whole));
    for key in [
        "final_time",
        "steps_accepted",
        "steps_rejected",
        "rhs_evaluations",
        "energy_error",
        "angular_momentum_error",
    ] {
        assert_eq!(a[key], b[key], "{key}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

fn campaign_error(text: &str, dir: &Path) -> String {
    let e = parse_campaign(text, "c.toml", dir).expect_err("a bad campaign");
    let msg = e.to_string();
    assert!(!msg.contains('\n'), "not one line: {msg}");
    assert_eq!(e.exit_code(), 2, "{msg}");
    msg
}

/// (d) bad campaign files: one line naming the field, exit code 2, never a panic.
#[test]
fn bad_campaign_files_give_one_line_errors() {
    let (dir, _) = campaign_dir("bad", GRID);
    let ok = parse_campaign(GRID, "c.toml", &dir);
    assert!(ok.is_ok(), "{:?}", ok.err());
    // impact.inertia reaches every run's scene; a model other than gaussian/uniform is refused
    let uniform = parse_campaign(
        &GRID.replace("rtol = 1e-8", "rtol = 1e-8\ninertia = \"uniform\""),
        "c.toml",
        &dir,
    )
    .expect("inertia = uniform");
    assert!(
        uniform
            .points
            .iter()
            .all(|p| p.plan.scene.model.inertia == InertiaModel::Uniform)
    );
    assert!(
        ok.unwrap()
            .points
            .iter()
            .all(|p| p.plan.scene.model.inertia == InertiaModel::Gaussian)
    );
    // impact.method reaches every run's scene; without rtol, Dop853 takes its per-step default 1e-8
    let dop =
        parse_campaign(&GRID.replace("rtol = 1e-8", "method = \"dop853\""), "c.toml", &dir).expect("method = dop853");
    assert!(
        dop.points
            .iter()
            .all(|p| p.plan.scene.integrator.method == Method::Dop853 && p.config.rtol == 1e-8)
    );
    let cases: [(String, &str); 12] = [
        (
            GRID.replace("rtol = 1e-8", "rtol = 1e-8\nmethod = \"leapfrog\""),
            "c.toml: impact.method: unknown variant `leapfrog`",
        ),
        (
            GRID.replace("rtol = 1e-8", "rtol = 1e-8\ninertia = \"hollow\""),
            "c.toml: impact.inertia: unknown variant `hollow`, expected `gaussian` or `uniform`",
        ),
        (
            GRID.replace("parallel = 2", "parallel = 2\nthreads = 4"),
            "c.toml: unknown field `threads` in [campaign]",
        ),
        (
            GRID.replace("rtol = 1e-8", "rtol = 1e-8\ntol = 3"),
            "c.toml: unknown field `tol` in [impact]",
        ),
        (
            GRID.replace("targets = [\"targets/tiny.csv\"]", "targets = []"),
            "c.toml: campaign.targets: must list at least one",
        ),
        (
            GRID.replace("targets/tiny.csv", "targets/missing.csv"),
            "c.toml: campaign.targets[0]: ",
        ),
        (
            GRID.replace("angles = [0, 90.0]", "angles = [0, 190.0]"),
            "c.toml: campaign.angles[1]: expected 0 to 180 degrees, got 190",
        ),
        (
            GRID.replace("angles = [0, 90.0]", "angles = [-5]"),
            "c.toml: campaign.angles[0]: expected 0 to 180 degrees, got -5",
        ),
        (
            GRID.replace("projectiles = [\"S1\", \"S2\"]", "projectiles = [\"P4\"]"),
            "c.toml: campaign.projectiles[0]: expected P1, P2, P3 or the id",
        ),
        (
            GRID.replace("t_end = 40.0", "t_end = -1.0"),
            "c.toml: impact.t_end: must be > 0",
        ),
        (GRID.replace("out = \"out\"\n", ""), "c.toml: campaign.out: missing"),
        (
            GRID.replace("angles = [0, 90.0]", "angles = \"0\""),
            "c.toml: campaign.angles: invalid type",
        ),
    ];
    for (text, expected) in &cases {
        let msg = campaign_error(text, &dir);
        assert!(msg.starts_with(expected), "expected {expected:?}, got {msg:?}");
    }
    // through the binary: `error: …` on one line, exit code 2, nothing run
    let file = dir.join("bad.toml");
    std::fs::write(&file, GRID.replace("angles = [0, 90.0]", "angles = [0, 190.0]")).unwrap();
    let out = bin(&["campaign", file.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = stderr(&out);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("error: ") && err.contains("campaign.angles[1]"),
        "{err}"
    );
    assert!(!dir.join("out").exists());
    let out = bin(&["campaign", dir.join("nope.toml").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("cannot read"), "{}", stderr(&out));
    let _ = std::fs::remove_dir_all(&dir);
}

/// (e) `rubblepile impact` (now a wrapper of `impact::run`) still runs an impact and names its flags in errors.
#[test]
fn impact_command_still_works() {
    let (dir, _) = campaign_dir("impact", GRID);
    let target = dir.join("targets/tiny.csv");
    let out_dir = dir.join("run");
    let args = |angle: &str| -> Vec<String> {
        [
            "impact",
            "--target",
            target.to_str().unwrap(),
            "--projectile-radius-km",
            "1",
            "--projectile-speed-km-s",
            "0.02",
            "--angle-deg",
            angle,
            "--contact-time-s",
            "5",
            "--t-end-s",
            "20",
            "--snapshots-s",
            "0,20",
            "--every-s",
            "5",
            "--out",
            out_dir.to_str().unwrap(),
            "--no-progress",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    let run = |a: &[String]| bin(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let out = run(&args("30"));
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    let mut lines = stdout.lines();
    assert!(
        lines
            .next()
            .unwrap()
            .starts_with("Impact of custom (1.00 km, 0.0 km/s) on "),
        "{stdout}"
    );
    assert!(lines.next().unwrap().starts_with("done: t = 20 s"), "{stdout}");
    for f in [
        "initial_bodies.csv",
        "impact.json",
        "scene.toml",
        "summary.json",
        "snapshots/1.csv",
    ] {
        assert!(out_dir.join(f).is_file(), "{f}");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("impact.json")).unwrap()).unwrap();
    assert_eq!(json["target"], target.display().to_string());
    assert_eq!(json["angle_deg"], 30.0);
    // the run directory's scene is an ordinary scene
    let scene = std::fs::read_to_string(out_dir.join("scene.toml")).unwrap();
    assert!(scene.contains("bodies_file = \"initial_bodies.csv\""));
    let calibrate = rubblepile::ellipsoid::scene::parse_toml(&scene, "scene.toml")
        .unwrap()
        .model
        .calibrate
        .unwrap();
    assert_eq!((calibrate.beta, calibrate.v), (10.0, 20.0));
    assert_eq!(
        calibrate.reading,
        rubblepile::ellipsoid::calibration::KappaReading::Printed
    );
    // existing directory without --force; bad angle: one line naming the flag
    let out = run(&args("30"));
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--force"), "{}", stderr(&out));
    let out = run(&args("200"));
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        stderr(&out).trim(),
        "error: --angle-deg: expected 0 to 180 degrees, got 200"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The committed Roig03 campaign files parse: 6 targets × 3 projectiles × 3 angles × 3 seeds (when the targets have
/// been built; otherwise the only complaint is a missing target), and the smoke campaign is 2 short runs. The main
/// grid calibrates κ with the reduced reading of Eq. 13 (the one that gives the paper's κ ≈ 10), its partner with
/// Eq. 14 as printed, and the scene each run writes says so.
#[test]
fn roig2003_campaign_files_are_valid() {
    use rubblepile::ellipsoid::calibration::KappaReading;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (file, runs, reading) in [
        ("campaign.toml", 162, KappaReading::Reduced),
        ("campaign_printed.toml", 162, KappaReading::Printed),
        ("smoke_campaign.toml", 2, KappaReading::Printed),
    ] {
        let path = root.join("analysis/roig2003").join(file);
        match load_campaign(&path) {
            Ok(c) => {
                assert_eq!(c.points.len(), runs, "{file}");
                assert!(c.points.iter().all(|p| p.config.rtol == 1e-6), "{file}");
                assert!(c.points.iter().all(|p| p.config.kappa_reading == reading), "{file}");
                let scene = c.points[0].plan.scene_toml();
                assert!(scene.contains(&format!("reading = \"{reading}\"")), "{file}: {scene}");
                let seeds = if runs == 162 { vec![1, 2, 3] } else { vec![1] };
                assert!(c.points.iter().all(|p| seeds.contains(&p.seed)), "{file}");
                assert!(c.out.file_name().unwrap().to_str().unwrap().starts_with("roig2003"));
                assert!(c.out.starts_with(root.join("runs")), "{}", c.out.display());
                if runs == 162 {
                    assert_eq!(c.points[0].name, "N30_T4_P1_z0_s1");
                    assert_eq!(c.points[1].name, "N30_T4_P1_z0_s2");
                    assert_eq!(c.points[161].name, "N200_T12_P3_z90_s3");
                    assert!(c.points.iter().all(|p| p.config.t_end == 10_000.0));
                } else {
                    assert_eq!(c.points[1].name, "N30_T4_P1_z90_s1");
                    assert_eq!(c.points[1].config.snapshots, [0.0, 100.0, 150.0]);
                }
            }
            Err(e) => assert!(e.to_string().contains(": campaign.targets["), "{file}: {e}"),
        }
    }
}

/// Shards of a job array: all N shards run separately into one directory and merged give the index of one
/// unsharded run (machine-dependent wall times aside), and the same run directories.
#[test]
fn shards_merged_give_the_unsharded_index() {
    let (dir, file) = campaign_dir("shards", GRID);
    let whole = load_campaign(&file).unwrap();
    run_campaign(&whole, &quiet()).unwrap();
    let mut sharded = load_campaign(&file).unwrap();
    sharded.out = dir.join("sharded");
    for i in 0..3 {
        let shard = Some(Shard { index: i, count: 3 });
        let r = run_campaign(&sharded, &CampaignOptions { shard, ..quiet() }).unwrap();
        let mine = (0..4).filter(|k| k % 3 == i).count();
        let ran = r
            .runs
            .iter()
            .filter(|x| x.action == Action::Start && x.status == RunStatus::Completed)
            .count();
        assert_eq!(ran, mine, "shard {i}: {}", r.one_line());
        assert!(dir.join(format!("sharded/campaign.shard-{i}-of-3.csv")).exists());
    }
    assert!(
        !dir.join("sharded/campaign.csv").exists(),
        "shards never write the campaign's index"
    );
    let merged = merge_campaign(&dir.join("sharded")).unwrap();
    assert_eq!(merged.completed(), 4);
    let machine_free = |rows: Vec<Vec<String>>| -> Vec<Vec<String>> {
        rows.into_iter()
            .map(|mut r| {
                r[7].clear(); // wall_seconds
                r
            })
            .collect()
    };
    assert_eq!(
        machine_free(read_csv(&dir.join("sharded/campaign.csv"))),
        machine_free(read_csv(&dir.join("out/campaign.csv")))
    );
    for p in &whole.points {
        for f in ["snapshots/0.csv", "timeseries.csv", "initial_bodies.csv"] {
            let a = std::fs::read(dir.join("out").join(&p.name).join(f)).unwrap();
            let b = std::fs::read(dir.join("sharded").join(&p.name).join(f)).unwrap();
            if f == "timeseries.csv" {
                // the last column is the wall clock
                let strip = |t: &[u8]| -> Vec<String> {
                    String::from_utf8_lossy(t)
                        .lines()
                        .map(|l| l.rsplit_once(',').unwrap().0.to_string())
                        .collect()
                };
                assert_eq!(strip(&a), strip(&b), "{} {f}", p.name);
            } else {
                assert_eq!(a, b, "{} {f}", p.name);
            }
        }
    }
    // Bad shard specifications are refused by name.
    for bad in ["3/3", "1", "a/2", "0/0"] {
        let e = bad.parse::<Shard>().unwrap_err();
        assert!(e.contains("--shard"), "{e}");
    }
    // The Slurm script runs every shard of this campaign.
    let o = bin(&["campaign", "slurm", file.to_str().unwrap(), "--tasks", "3"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let script = std::fs::read_to_string(dir.join("out/campaign.slurm")).unwrap();
    assert!(script.starts_with("#!/bin/bash\n"), "{script}");
    assert!(script.contains("#SBATCH --array=0-2\n"), "{script}");
    assert!(script.contains("--shard $SLURM_ARRAY_TASK_ID/3"), "{script}");
    assert!(
        script.contains(&format!("campaign merge {}", dir.join("out").display())),
        "{script}"
    );
    // The merge command through the binary.
    let o = bin(&["campaign", "merge", dir.join("sharded").to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("4 completed"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A default build started by `mpirun` with several ranks must not run (every rank would run the whole grid into
/// the same directories): one line saying how to build with MPI.
#[cfg(not(feature = "mpi"))]
#[test]
fn a_default_build_under_mpirun_refuses_to_run() {
    let (dir, file) = campaign_dir("no-mpi", GRID);
    let o = Command::new(env!("CARGO_BIN_EXE_rubblepile"))
        .args(["campaign", file.to_str().unwrap(), "--no-progress"])
        .env("OMPI_COMM_WORLD_SIZE", "3")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--features mpi"), "{}", stderr(&o));
    assert!(!dir.join("out").exists(), "nothing was run");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every file of every run directory, with the machine-dependent wall-clock fields blanked.
#[cfg(feature = "mpi")]
fn run_files(out: &Path, points: &[String]) -> Vec<(String, String)> {
    let mut files = Vec::new();
    for name in points {
        for (p, bytes, _) in tree(&out.join(name)) {
            let rel = p.strip_prefix(out).unwrap().display().to_string();
            let text = String::from_utf8_lossy(&bytes).into_owned();
            let text = if rel.ends_with("timeseries.csv") {
                text.lines()
                    .map(|l| l.rsplit_once(',').unwrap().0.to_string() + "\n")
                    .collect()
            } else if rel.ends_with("manifest.txt") {
                // the rows of the files above carry wall-clock columns, and the closing line sums every row
                text.lines()
                    .filter(|l| {
                        !(l.ends_with("= timeseries.csv") || l.ends_with("= summary.json") || l.starts_with("# end"))
                    })
                    .map(|l| l.to_string() + "\n")
                    .collect()
            } else if rel.ends_with(".json") {
                text.lines()
                    .filter(|l| !l.contains("wall_seconds"))
                    .map(|l| l.to_string() + "\n")
                    .collect()
            } else {
                text
            };
            files.push((rel, text));
        }
    }
    files
}

#[cfg(feature = "mpi")]
fn mpirun(ranks: usize, args: &[&str]) -> Command {
    let mut c = Command::new("mpirun");
    c.args([
        "-n",
        &ranks.to_string(),
        "--oversubscribe",
        env!("CARGO_BIN_EXE_rubblepile"),
    ])
    .args(args)
    .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
    .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1");
    c
}

#[cfg(feature = "mpi")]
fn index_without_wall(path: &Path) -> Vec<Vec<String>> {
    read_csv(path)
        .into_iter()
        .map(|mut r| {
            r[7].clear();
            r
        })
        .collect()
}

/// Three MPI ranks (one coordinator, two workers) give the run directories and the index of the threaded runner.
#[cfg(feature = "mpi")]
#[test]
fn mpi_campaign_matches_the_threaded_runner() {
    let (dir, file) = campaign_dir("mpi", GRID);
    let campaign = load_campaign(&file).unwrap();
    run_campaign(&campaign, &quiet()).unwrap();
    let o = mpirun(
        3,
        &[
            "campaign",
            file.to_str().unwrap(),
            "--out",
            dir.join("mpi").to_str().unwrap(),
            "--no-progress",
        ],
    )
    .output()
    .expect("mpirun (Open MPI) must be installed for the mpi feature's tests");
    assert!(o.status.success(), "{}", stderr(&o));
    let names: Vec<String> = campaign.points.iter().map(|p| p.name.clone()).collect();
    assert_eq!(
        index_without_wall(&dir.join("mpi/campaign.csv")),
        index_without_wall(&dir.join("out/campaign.csv"))
    );
    let (a, b) = (run_files(&dir.join("out"), &names), run_files(&dir.join("mpi"), &names));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x, y, "{}", x.0);
    }
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("(rank 1)") && out.contains("(rank 2)"),
        "both workers ran: {out}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A worker rank killed (SIGKILL) mid-campaign: the index on disk stays a valid table, and running the command
/// again completes the campaign with nothing lost or duplicated (the same index as an uninterrupted run).
#[cfg(feature = "mpi")]
#[test]
fn a_rank_killed_mid_campaign_loses_nothing() {
    // Longer runs (to 3000 s) with checkpoints at every output sample, so that the kill lands mid-run.
    let grid = GRID
        .replace("t_end = 40.0", "t_end = 3000.0")
        .replace("angles = [0, 90.0]", "angles = [0, 45.0, 90.0]");
    let (dir, file) = campaign_dir("mpi-kill", &grid);
    let mpi_out = dir.join("mpi");
    let args = [
        "campaign",
        file.to_str().unwrap(),
        "--out",
        mpi_out.to_str().unwrap(),
        "--no-progress",
    ];
    let mut child = mpirun(3, &[&args[..], &["--checkpoint-every-sim-s", "0"]].concat())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // Wait until a run has completed and another is running, then kill worker rank 1.
    let index = dir.join("mpi/campaign.csv");
    let t0 = std::time::Instant::now();
    let victim = loop {
        assert!(t0.elapsed().as_secs() < 120, "the campaign never got going");
        std::thread::sleep(std::time::Duration::from_millis(20));
        let Ok(text) = std::fs::read_to_string(&index) else {
            continue;
        };
        if !(text.contains(",completed,") && text.contains(",running,")) {
            continue;
        }
        // The rank-1 process: its environment names its rank.
        let pid = std::fs::read_dir("/proc")
            .unwrap()
            .filter_map(|e| e.ok())
            .find_map(|e| {
                let pid: u32 = e.file_name().to_str()?.parse().ok()?;
                let cmd = std::fs::read(format!("/proc/{pid}/cmdline")).ok()?;
                let env = std::fs::read(format!("/proc/{pid}/environ")).ok()?;
                let has = |hay: &[u8], needle: &[u8]| hay.windows(needle.len()).any(|w| w == needle);
                (has(&cmd, file.to_str()?.as_bytes()) && has(&env, b"OMPI_COMM_WORLD_RANK=1\0")).then_some(pid)
            });
        if let Some(pid) = pid {
            break pid;
        }
    };
    Command::new("kill").args(["-9", &victim.to_string()]).status().unwrap();
    let status = child.wait().unwrap();
    assert!(!status.success(), "Open MPI ends the job when a rank dies");
    // The index on disk is a whole table of the grid (replaced atomically, never half written).
    let rows = read_csv(&index);
    assert_eq!(rows.len(), 6);
    let done_before = rows.iter().filter(|r| r[6] == "completed").count();
    assert!((1..6).contains(&done_before), "{rows:?}");
    // A run may finish (its summary.json written) after the index last said "running" and before the kill: the
    // restart counts what the run directories say, which is at least what the index said.
    let done_on_disk = rows
        .iter()
        .filter(|r| {
            std::fs::read_to_string(mpi_out.join(&r[0]).join("summary.json"))
                .is_ok_and(|t| serde_json::from_str::<serde_json::Value>(&t).unwrap()["status"] == "completed")
        })
        .count();
    assert!(done_on_disk >= done_before, "{rows:?}");
    // Again: the rest is completed, nothing is run twice.
    let o = mpirun(3, &args).output().unwrap();
    assert!(
        o.status.success(),
        "{}\n{}",
        stderr(&o),
        std::fs::read_to_string(&index).unwrap_or_default()
    );
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains(&format!("{} runs to do of 6", 6 - done_on_disk)), "{out}");
    let reference = load_campaign(&file).unwrap();
    run_campaign(&reference, &quiet()).unwrap();
    assert_eq!(
        index_without_wall(&index),
        index_without_wall(&dir.join("out/campaign.csv"))
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Under MPI, a campaign directory another process writes: rank 0 is refused at once and sends the worker ranks
/// home before it says so, so the job ends with the one-line refusal instead of hanging.
#[cfg(feature = "mpi")]
#[test]
fn mpi_campaign_into_a_directory_being_written_is_refused_without_hanging() {
    let (dir, file) = campaign_dir("mpi-locked", GRID);
    let out = dir.join("mpi");
    std::fs::create_dir_all(&out).unwrap();
    let lock = rubblepile::io::run_lock::DirLock::acquire(&out).unwrap();
    let mut child = mpirun(
        3,
        &[
            "campaign",
            file.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--no-progress",
        ],
    )
    .stdout(std::process::Stdio::piped())
    .stderr(std::process::Stdio::piped())
    .spawn()
    .unwrap();
    let t0 = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if t0.elapsed().as_secs() > 120 {
            let _ = child.kill();
            panic!("mpirun hung on a refused campaign directory");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    let o = child.wait_with_output().unwrap();
    assert!(!o.status.success(), "{}", stderr(&o));
    let expected = format!(
        "error: {} is being written by another rubblepile process (pid {})",
        out.display(),
        std::process::id()
    );
    assert!(stderr(&o).contains(&expected), "{}", stderr(&o));
    assert!(!out.join("campaign.csv").exists(), "nothing written");
    drop(lock);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `campaign slurm` with every scheduler option: each lands on its own `#SBATCH` line, the array carries the
/// throttle, the tasks run the named binary; without them none of those lines is written; a bad value is refused
/// naming its option, before anything is written.
#[test]
fn slurm_script_carries_the_scheduler_options() {
    let (dir, file) = campaign_dir("slurm-options", GRID);
    let f = file.to_str().unwrap();
    let o = bin(&[
        "campaign",
        "slurm",
        f,
        "--tasks",
        "8",
        "--threads-per-task",
        "4",
        "--time",
        "1-02:30:00",
        "--partition",
        "short",
        "--account",
        "proj-42",
        "--mem",
        "16G",
        "--throttle",
        "3",
        "--binary",
        "/opt/rp/bin/rubblepile",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let script = std::fs::read_to_string(dir.join("out/campaign.slurm")).unwrap();
    let sbatch: Vec<&str> = script.lines().filter(|l| l.starts_with("#SBATCH")).collect();
    let out = dir.join("out");
    let expected = [
        "#SBATCH --job-name=rubblepile-campaign".to_string(),
        "#SBATCH --array=0-7%3".to_string(),
        "#SBATCH --ntasks=1".to_string(),
        "#SBATCH --cpus-per-task=4".to_string(),
        "#SBATCH --time=1-02:30:00".to_string(),
        "#SBATCH --partition=short".to_string(),
        "#SBATCH --account=proj-42".to_string(),
        "#SBATCH --mem=16G".to_string(),
        format!("#SBATCH --output={}/slurm-%A_%a.out", out.display()),
    ];
    assert_eq!(
        sbatch,
        expected.iter().map(String::as_str).collect::<Vec<_>>(),
        "{script}"
    );
    let srun: Vec<&str> = script.lines().filter(|l| l.starts_with("srun ")).collect();
    assert_eq!(srun.len(), 1, "{script}");
    assert!(srun[0].starts_with("srun /opt/rp/bin/rubblepile campaign "), "{script}");
    assert!(srun[0].contains("--shard $SLURM_ARRAY_TASK_ID/8"), "{script}");
    assert!(
        script.contains("--wrap '/opt/rp/bin/rubblepile campaign merge"),
        "{script}"
    );

    // Without the options: the plain array, the scheduler's defaults, this binary by its absolute path.
    let o = bin(&["campaign", "slurm", f, "--tasks", "2", "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let plain = std::fs::read_to_string(out.join("campaign.slurm")).unwrap();
    assert!(plain.contains("#SBATCH --array=0-1\n"), "{plain}");
    for opt in ["--time", "--partition", "--account", "--mem"] {
        assert!(!plain.contains(&format!("#SBATCH {opt}")), "{opt}: {plain}");
    }
    let exe = std::fs::canonicalize(env!("CARGO_BIN_EXE_rubblepile")).unwrap();
    assert!(plain.contains(&format!("srun {} campaign", exe.display())), "{plain}");

    std::fs::remove_file(out.join("campaign.slurm")).unwrap();
    for (opt, value) in [
        ("--time", "2 hours"),
        ("--time", "1-"),
        ("--mem", "16GB"),
        ("--partition", "a;rm -rf"),
        ("--account", ""),
        ("--throttle", "0"),
    ] {
        let o = bin(&["campaign", "slurm", f, "--tasks", "2", opt, value]);
        assert_eq!(o.status.code(), Some(2), "{opt} {value}: {}", stderr(&o));
        assert!(stderr(&o).contains(opt), "{opt} {value}: {}", stderr(&o));
        assert!(
            !out.join("campaign.slurm").exists(),
            "{opt} {value}: a script was written"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
