//! README truth (issue 41): the first-run output the README quotes (the ```text block after "ends with") is what
//! the first command prints — the same lines in the same order, the same words, integers (steps, rejected steps,
//! RHS evaluations, frames, t) and file names; floating-point figures and millisecond timings may differ.

use std::path::{Path, PathBuf};

/// The README's first command, as run here: `rubblepile run --out runs/demo` (what `cargo run --release -- run
/// --out runs/demo` runs).
const OUT: &str = "runs/demo";

fn readme() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap()
}

/// The lines of the first ```text block after the first line of `text` that contains `marker`.
fn quoted_block(text: &str, marker: &str) -> Vec<String> {
    let after = &text[text.find(marker).expect("the marker is in the README")..];
    let start = after.find("```text\n").expect("a ```text block follows") + "```text\n".len();
    let body = &after[start..];
    let end = body.find("```").expect("the block ends");
    body[..end].lines().map(str::to_string).collect()
}

/// A line with every floating-point number (one with a `.` or an exponent) and every count of milliseconds
/// replaced by `#`: what may differ between two runs or machines. Integers, words and paths stay.
fn shape(line: &str) -> String {
    let b = line.as_bytes();
    let mut out = String::new();
    let mut i = 0;
    while i < b.len() {
        let starts_number =
            b[i].is_ascii_digit() && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_'));
        if !starts_number {
            out.push(b[i] as char);
            i += 1;
            continue;
        }
        let mut j = i;
        while j < b.len() && b[j].is_ascii_digit() {
            j += 1;
        }
        let mut float = false;
        if j + 1 < b.len() && b[j] == b'.' && b[j + 1].is_ascii_digit() {
            float = true;
            j += 1;
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
        }
        if j < b.len()
            && b[j] == b'e'
            && j + 1 < b.len()
            && (b[j + 1] == b'-' || b[j + 1] == b'+' || b[j + 1].is_ascii_digit())
        {
            float = true;
            j += 1;
            if b[j] == b'-' || b[j] == b'+' {
                j += 1;
            }
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
        }
        let timing = line[j..].starts_with(" ms");
        if float || timing {
            out.push('#');
        } else {
            out.push_str(&line[i..j]);
        }
        i = j;
    }
    out
}

#[test]
fn shape_keeps_integers_and_names_and_hides_floats_and_timings() {
    assert_eq!(
        shape("done: t = 600 s, wall 0.10 s, steps 100 (5 rejected), energy error 3.8e-14, |dP| 5.4e-15"),
        "done: t = 600 s, wall # s, steps 100 (5 rejected), energy error #, |dP| #"
    );
    assert_eq!(
        shape("rendered 61 frames in 2.8 s (median 7 ms per frame)"),
        "rendered 61 frames in # s (median # ms per frame)"
    );
    assert_eq!(
        shape("look at it: runs/demo/frames/run.gif"),
        "look at it: runs/demo/frames/run.gif"
    );
    assert_eq!(shape("max||q|-1| 1.2e-12, N30_T4"), "max||q|-1| #, N30_T4");
}

#[test]
fn the_readme_quotes_what_the_first_command_prints() {
    let quoted = quoted_block(&readme(), "and ends with");
    assert!(quoted.len() >= 3, "{quoted:?}");
    let cwd: PathBuf = std::env::temp_dir().join(format!("rubblepile-readme-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&cwd);
    std::fs::create_dir_all(&cwd).unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_rubblepile"))
        .args(["run", "--out", OUT])
        .current_dir(&cwd)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let printed: Vec<String> = String::from_utf8_lossy(&o.stdout).lines().map(str::to_string).collect();
    let quoted_shape: Vec<String> = quoted.iter().map(|l| shape(l)).collect();
    let printed_shape: Vec<String> = printed.iter().map(|l| shape(l)).collect();
    assert_eq!(
        quoted_shape,
        printed_shape,
        "README.md's first-run output is stale; the run printed:\n{}",
        printed.join("\n")
    );
    // Every file the run announces exists where it says.
    for line in &printed {
        for word in line.split_whitespace() {
            if word.starts_with(OUT) {
                assert!(cwd.join(word).is_file(), "{word} announced but not written");
            }
        }
    }
    let _ = std::fs::remove_dir_all(&cwd);
}
