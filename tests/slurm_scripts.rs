//! `campaign slurm` writes job scripts that run only what they say (issue 53). A property test generates paths
//! (the binary's, the campaign file's and the campaign directory's) holding spaces, quotes, `;`, `$(…)`, backticks,
//! `#`, `%`, backslashes and globs, writes the script with them, and runs it (and the submit and merge lines of its
//! header) under stub `srun`, `sbatch` and `rubblepile` programs that record their arguments: every path arrives
//! intact, as one argument, and nothing injected runs (no `PWNED` file appears anywhere). The `#SBATCH --output`
//! line is read as sbatch reads its directives (backslash escapes, quotes, `#` comments, `%%`). Values with a
//! newline, and out-of-range `--time` and `--mem`, are refused by name before anything is written. Everything is
//! written below the test's temporary directory.

mod common;
use common::{describe, temp_dir};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Pieces a hostile path is made of: each injection would create a file named `PWNED` if the shell (or sbatch) ran
/// it.
const PIECES: [&str; 16] = [
    "a",
    " ",
    "it's",
    "\"q\"",
    ";touch PWNED;",
    "$(touch PWNED)",
    "`touch PWNED`",
    "${IFS}",
    "#x",
    "%A%%",
    "\\",
    "*?[x]",
    "&& touch PWNED",
    "|touch PWNED",
    "~",
    "\t",
];

/// A directory or file name of one to four pieces.
fn name() -> impl Strategy<Value = String> {
    prop::collection::vec(prop::sample::select(PIECES.to_vec()), 1..5).prop_map(|v| v.concat())
}

/// sbatch's reading of one `#SBATCH` argument (its `_get_argument`): a backslash keeps the next character as it
/// is, `'…'` and `"…"` group, an unescaped `#` outside quotes ends the line, white space ends the argument.
fn sbatch_argument(line: &str) -> String {
    let mut out = String::new();
    let (mut escaped, mut quote) = (false, None::<char>);
    for c in line.trim_start().chars() {
        if escaped {
            escaped = false;
            out.push(c);
        } else if c == '\\' {
            escaped = true;
        } else if let Some(q) = quote {
            if c == q {
                quote = None;
            } else {
                out.push(c);
            }
        } else if c == '"' || c == '\'' {
            quote = Some(c);
        } else if c == '#' || c.is_whitespace() {
            break;
        } else {
            out.push(c);
        }
    }
    out
}

/// Writes an executable shell script.
fn executable(path: &Path, text: &str) {
    std::fs::write(path, text).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// The NUL-separated argument lists recorded in `path` (one list a line of records ending in `\n`).
fn records(path: &Path) -> Vec<Vec<String>> {
    let Ok(bytes) = std::fs::read(path) else {
        return Vec::new();
    };
    String::from_utf8(bytes)
        .unwrap()
        .split('\u{1}')
        .filter(|r| !r.is_empty())
        .map(|r| r.split('\0').filter(|a| !a.is_empty()).map(str::to_string).collect())
        .collect()
}

/// Every path below `dir` whose name holds `PWNED` (what an injection would have made).
fn pwned(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let e = e.unwrap();
            if e.file_name().to_string_lossy().starts_with("PWNED") {
                out.push(e.path());
            }
            if e.file_type().unwrap().is_dir() {
                stack.push(e.path());
            }
        }
    }
    out
}

/// One case: the binary in `base/<b>/`, the campaign file `base/<f>/<f>.toml`, the directory `base/<o>`.
fn run_case(base: &Path, b: &str, f: &str, o: &str) -> Result<(), String> {
    let stubs = base.join("stubs");
    std::fs::create_dir_all(&stubs).unwrap();
    let record = base.join("record");
    // srun runs its command; sbatch records its arguments, prints a job id, and runs a --wrap command with sh.
    executable(&stubs.join("srun"), "#!/bin/sh\nexec \"$@\"\n");
    executable(
        &stubs.join("sbatch"),
        "#!/bin/sh\nprintf 'sbatch\\0' >> \"$RECORD\"\nfor a in \"$@\"; do printf '%s\\0' \"$a\" >> \"$RECORD\"; done\n\
         printf '\\001' >> \"$RECORD\"\nwrap=\nwhile [ $# -gt 0 ]; do if [ \"$1\" = --wrap ]; then wrap=$2; fi; shift; done\n\
         if [ -n \"$wrap\" ]; then sh -c \"$wrap\"; else echo 42; fi\n",
    );
    let bin_dir = base.join(b);
    std::fs::create_dir_all(&bin_dir).unwrap();
    let bin = bin_dir.join("rubblepile");
    executable(
        &bin,
        "#!/bin/sh\nprintf 'rubblepile\\0' >> \"$RECORD\"\nfor a in \"$@\"; do printf '%s\\0' \"$a\" >> \"$RECORD\"; done\n\
         printf '\\001' >> \"$RECORD\"\n",
    );
    let file_dir = base.join(f);
    std::fs::create_dir_all(&file_dir).unwrap();
    let file = file_dir.join(format!("{f}.toml"));
    std::fs::write(
        &file,
        format!(
            "[campaign]\nout = \"unused\"\ntargets = [\"{}\"]\nprojectiles = [\"P2\"]\nangles = [45.0]\nseeds = [1, 2]\n",
            root().join("targets/N30_T4.csv").display()
        ),
    )
    .unwrap();
    let out = base.join(o);
    let o = Command::new(env!("CARGO_BIN_EXE_rubblepile"))
        .args(["campaign", "slurm"])
        .arg(&file)
        .args(["--tasks", "3", "--out"])
        .arg(&out)
        .arg("--binary")
        .arg(&bin)
        .current_dir(base)
        .output()
        .unwrap();
    if !o.status.success() {
        return Err(format!("campaign slurm: {}", describe(&o)));
    }
    let script_path = out.join("campaign.slurm");
    let script = std::fs::read_to_string(&script_path).map_err(|e| e.to_string())?;
    let sh = |cmd: &mut Command| {
        cmd.env(
            "PATH",
            format!("{}:{}", stubs.display(), std::env::var("PATH").unwrap()),
        )
        .env("RECORD", &record)
        .env("SLURM_ARRAY_TASK_ID", "2")
        .env("SLURM_CPUS_PER_TASK", "4")
        .current_dir(base)
        .output()
        .unwrap()
    };
    // The array task.
    let o = sh(Command::new("bash").arg(&script_path));
    if !o.status.success() {
        return Err(format!("the script failed: {}\n{script}", describe(&o)));
    }
    // The two lines of the header, as a user pastes them into a shell.
    let line = |prefix: &str| {
        script
            .lines()
            .find_map(|l| l.strip_prefix(prefix))
            .map(str::to_string)
            .ok_or(format!("no {prefix:?} line:\n{script}"))
    };
    let submit = line("# Submit:  ")?;
    let then = line("# Then:    ")?;
    let o = sh(Command::new("bash").arg("-c").arg(format!("{submit}\n{then}")));
    if !o.status.success() {
        return Err(format!("the header's commands failed: {}\n{script}", describe(&o)));
    }
    let s = |p: &Path| p.to_str().unwrap().to_string();
    let want: Vec<Vec<String>> = vec![
        [
            "rubblepile",
            "campaign",
            &s(&file),
            "--out",
            &s(&out),
            "--shard",
            "2/3",
            "--parallel",
            "1",
            "--no-progress",
        ]
        .map(String::from)
        .to_vec(),
        ["sbatch", "--parsable", &s(&script_path)].map(String::from).to_vec(),
        [
            "sbatch",
            "--dependency=afterany:42",
            "--wrap",
            &format!("{} campaign merge {}", sh_word(&bin), sh_word(&out)),
        ]
        .map(String::from)
        .to_vec(),
        ["rubblepile", "campaign", "merge", &s(&out)].map(String::from).to_vec(),
    ];
    let got = records(&record);
    if got != want {
        return Err(format!("arguments differ:\n got:  {got:?}\n want: {want:?}\n{script}"));
    }
    let output = script
        .lines()
        .find_map(|l| l.strip_prefix("#SBATCH --output="))
        .ok_or("no --output line")?;
    let read = sbatch_argument(output)
        .replace("%%", "\u{0}")
        .replace("%A_%a", "JOB_TASK");
    let want_output = format!("{}/slurm-JOB_TASK.out", s(&out).replace("%", "\u{0}"));
    if read != want_output {
        return Err(format!("sbatch reads --output as {read:?}, want {want_output:?}"));
    }
    let planted = pwned(base);
    if !planted.is_empty() {
        return Err(format!("an injected command ran: {planted:?}\n{script}"));
    }
    Ok(())
}

/// The word the script writes for a path: POSIX single quotes around it, each `'` inside written `'\''`. The
/// script quotes every word holding more than letters, digits and `_ . / - : , + = @ %`; the paths here always
/// hold a space (`bin …`, `out …`), so they are always quoted.
fn sh_word(p: &Path) -> String {
    let s = p.to_str().unwrap();
    assert!(s.contains(' '), "{s:?} would be written unquoted");
    format!("'{}'", s.replace('\'', "'\\''"))
}

#[test]
fn job_scripts_pass_every_path_intact_and_run_nothing_injected() {
    let config = Config {
        cases: 24,
        failure_persistence: None,
        max_shrink_iters: 32,
        ..Config::default()
    };
    let mut runner = TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    let count = std::sync::atomic::AtomicUsize::new(0);
    let result = runner.run(&(name(), name(), name()), |(b, f, o)| {
        let k = count.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        let base = temp_dir(&format!("slurm-{k}"));
        // The three names must differ, or the directories would be one.
        let (b, f, o) = (format!("bin {b}"), format!("file {f}"), format!("out {o}"));
        run_case(&base, &b, &f, &o).map_err(|e| TestCaseError::fail(format!("{b:?} {f:?} {o:?}: {e}")))
    });
    if let Err(e) = result {
        panic!("{e}");
    }
    assert!(count.into_inner() >= 24);
}

#[test]
fn bad_scheduler_values_and_newlines_are_refused_by_name_before_anything_is_written() {
    let base = temp_dir("slurm-bad");
    let file = base.join("c.toml");
    std::fs::write(
        &file,
        format!(
            "[campaign]\nout = \"out\"\ntargets = [\"{}\"]\nprojectiles = [\"P2\"]\nangles = [45.0]\nseeds = [1]\n",
            root().join("targets/N30_T4.csv").display()
        ),
    )
    .unwrap();
    let run = |extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_rubblepile"))
            .args(["campaign", "slurm", "c.toml", "--tasks", "2"])
            .args(extra)
            .current_dir(&base)
            .output()
            .unwrap()
    };
    for (extra, needle) in [
        (&["--time", "1:99:99"][..], "--time: must be a Slurm time limit"),
        (&["--time", "1-25:00"], "hours after days must be below 24"),
        (&["--time", "400-0"], "at most 365 days"),
        (&["--mem", "99999999999999999999G"], "--mem: must be a whole number"),
        (&["--mem", "100T"], "--mem: must be at most 64T"),
        (&["--partition", "a b"], "--partition: must be a name"),
        (&["--account", "x$(id)"], "--account: must be a name"),
        (&["--out", "a\nb"], "--out: must not hold a newline"),
        (&["--binary", "/bin/rp\nrm -rf x"], "--binary: must not hold a newline"),
    ] {
        let o = run(extra);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", describe(&o));
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(stderr.lines().count(), 1, "{extra:?}: {stderr}");
        assert!(stderr.contains(needle), "{extra:?}: expected {needle:?} in {stderr}");
        assert!(!base.join("out").exists(), "{extra:?}: something was written");
    }
    // A relative binary is made absolute.
    let o = run(&["--binary", "bin/rp"]);
    assert!(o.status.success(), "{}", describe(&o));
    let script = std::fs::read_to_string(base.join("out/campaign.slurm")).unwrap();
    assert!(
        script.contains(&format!(
            "srun {}/bin/rp campaign ",
            std::fs::canonicalize(&base).unwrap().display()
        )) || script.contains(&format!("srun {}/bin/rp campaign ", base.display())),
        "{script}"
    );
}
