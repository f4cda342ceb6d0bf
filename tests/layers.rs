//! The crate's layering (the table in `src/lib.rs`'s doc comment): every `crate::` path in `src/` outside comments
//! goes from a top-level module to one of a strictly lower layer, so that there is no import cycle among the
//! top-level modules and no arrow up (an engine never sees the driver, the analysis or the command line).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn src() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// The layer of each top-level module, read from the `- **Ln**: `a`, `b` — …` lines of `src/lib.rs`.
fn layers() -> BTreeMap<String, usize> {
    let lib = std::fs::read_to_string(src().join("lib.rs")).unwrap();
    let mut out = BTreeMap::new();
    for line in lib.lines() {
        let Some(rest) = line.strip_prefix("//! - **L") else {
            continue;
        };
        let (n, rest) = rest.split_once("**:").expect("`- **Ln**: ...`");
        let layer: usize = n.parse().expect("a layer number");
        let names = rest.split(" — ").next().unwrap();
        for name in names.split(',') {
            out.insert(name.trim().trim_matches('`').to_string(), layer);
        }
    }
    out
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// `(from module, to module, file:line)` of every `crate::x` path outside comments.
fn imports() -> Vec<(String, String, String)> {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    let mut out = Vec::new();
    for f in files {
        let rel = f.strip_prefix(src()).unwrap().to_path_buf();
        let first = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy()
            .to_string();
        let from = first.trim_end_matches(".rs").to_string();
        if from == "lib" || from == "main" {
            continue;
        }
        for (k, line) in std::fs::read_to_string(&f).unwrap().lines().enumerate() {
            if line.trim_start().starts_with("//") {
                continue;
            }
            for (i, _) in line.match_indices("crate::") {
                if i > 0 && line.as_bytes()[i - 1].is_ascii_alphanumeric() {
                    continue;
                }
                let to: String = line[i + 7..]
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                    .collect();
                if to != from {
                    out.push((from.clone(), to, format!("src/{}:{}", rel.display(), k + 1)));
                }
            }
        }
    }
    out
}

#[test]
fn every_top_level_module_has_a_layer() {
    let layers = layers();
    let lib = std::fs::read_to_string(src().join("lib.rs")).unwrap();
    let modules: Vec<&str> = lib
        .lines()
        .filter_map(|l| l.strip_prefix("pub mod ").and_then(|r| r.strip_suffix(';')))
        .collect();
    assert!(modules.len() >= 10, "{modules:?}");
    for m in &modules {
        assert!(
            layers.contains_key(*m),
            "module `{m}` is in no layer of src/lib.rs's table"
        );
    }
    for m in layers.keys() {
        assert!(
            modules.contains(&m.as_str()),
            "the layer table names `{m}`, which is no module"
        );
    }
}

#[test]
fn imports_only_go_down_the_layers() {
    let layers = layers();
    let mut upward = Vec::new();
    for (from, to, at) in imports() {
        let (Some(&lf), Some(&lt)) = (layers.get(&from), layers.get(&to)) else {
            upward.push(format!("{at}: crate::{to} from `{from}` (a module outside the table)"));
            continue;
        };
        if lt >= lf {
            upward.push(format!("{at}: `{from}` (L{lf}) uses crate::{to} (L{lt})"));
        }
    }
    assert!(
        upward.is_empty(),
        "{} imports do not go down:\n{}",
        upward.len(),
        upward.join("\n")
    );
}

/// The command line parses and dispatches; science and timed systems live in `analysis` and `bench`. Its size is a
/// cheap guard against logic creeping back in.
#[test]
fn the_command_line_stays_small() {
    let mut files = Vec::new();
    rust_files(&src().join("cli"), &mut files);
    let lines: usize = files
        .iter()
        .map(|f| std::fs::read_to_string(f).unwrap().lines().count())
        .sum();
    assert!(
        lines <= 2000,
        "src/cli/ has {lines} lines (at most 2000: move logic to analysis/ or bench/)"
    );
}
