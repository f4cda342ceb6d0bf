//! The hand-written part of a generated report: `NOTES.md` in the report's output directory, appended verbatim
//! after the generated sections (the Richardson11 and Zhang17 reports), so that a regenerated `REPORT.md` keeps
//! the discussion that no run can produce.

use std::path::Path;

/// The notes file's name in a report's output directory.
pub const NOTES_FILE: &str = "NOTES.md";

/// The line in `NOTES.md` that [`append_notes`] replaces by the tally of the notes' verdicts ([`tally`]).
pub const TALLY_MARKER: &str = "<!-- tally: computed by rubblepile report -->";

/// Appends `dir/NOTES.md` to `md` after a blank line (and a final newline), verbatim but for the line
/// [`TALLY_MARKER`], which becomes the [`tally`] of the notes' table; nothing when the file is absent or unreadable
/// (a report without notes is still a report).
pub fn append_notes(md: &mut String, dir: &Path) {
    if let Ok(text) = std::fs::read_to_string(dir.join(NOTES_FILE)) {
        md.push('\n');
        md.push_str(&with_tally(&text));
        md.push('\n');
    }
}

/// `text` with each line equal to [`TALLY_MARKER`] replaced by [`tally`]`(text)`.
pub fn with_tally(text: &str) -> String {
    if !text.lines().any(|l| l.trim() == TALLY_MARKER) {
        return text.to_string();
    }
    let counted = tally(text);
    let mut out = String::with_capacity(text.len() + counted.len());
    for line in text.split_inclusive('\n') {
        if line.trim() == TALLY_MARKER {
            out.push_str(&counted);
            if line.ends_with('\n') {
                out.push('\n');
            }
        } else {
            out.push_str(line);
        }
    }
    out
}

/// The rows of the notes' comparison table by verdict, counted from the table itself: every line `| N | item |
/// paper | ours | verdict | … |` whose first cell is a row number, its fifth cell read as **reproduced**, **partly**
/// or **not** (its first word, bold or not). A row with another verdict is listed as such, so that a typo shows.
pub fn tally(text: &str) -> String {
    let mut groups: Vec<(String, Vec<u32>)> = ["reproduced", "partly", "not"]
        .iter()
        .map(|v| (v.to_string(), Vec::new()))
        .collect();
    for line in text.lines() {
        let cells = cells_of(line);
        let (Some(row), Some(verdict)) = (cells.first().and_then(|c| c.parse::<u32>().ok()), cells.get(4)) else {
            continue;
        };
        let word = verdict
            .trim_matches('*')
            .split_whitespace()
            .next()
            .unwrap_or("(empty)")
            .trim_matches(|c: char| !c.is_alphanumeric())
            .to_lowercase();
        match groups.iter_mut().find(|(v, _)| *v == word) {
            Some((_, rows)) => rows.push(row),
            None => groups.push((word, vec![row])),
        }
    }
    let total: usize = groups.iter().map(|(_, r)| r.len()).sum();
    let parts: Vec<String> = groups
        .iter()
        .map(|(verdict, rows)| {
            let list: Vec<String> = rows.iter().map(u32::to_string).collect();
            let mut name = verdict.clone();
            name[..1].make_ascii_uppercase();
            if rows.is_empty() {
                format!("{name}: none (0).")
            } else {
                format!("{name}: rows {} ({}).", list.join(", "), rows.len())
            }
        })
        .collect();
    format!(
        "{} Of {total} rows (counted from the table above by `rubblepile report`).",
        parts.join(" ")
    )
}

/// The cells of a Markdown table row, trimmed; `\|` inside a cell is text, not a border.
fn cells_of(line: &str) -> Vec<String> {
    let body = line.trim().strip_prefix('|').unwrap_or(line.trim());
    let mut cells = vec![String::new()];
    let mut chars = body.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\\' if chars.peek() == Some(&'|') => {
                cells.last_mut().expect("one cell at least").push('|');
                chars.next();
            }
            '|' => cells.push(String::new()),
            _ => cells.last_mut().expect("one cell at least").push(c),
        }
    }
    if cells.last().is_some_and(|c| c.trim().is_empty()) {
        cells.pop();
    }
    cells.into_iter().map(|c| c.trim().to_string()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn notes_are_appended_verbatim_after_a_blank_line_and_absent_notes_add_nothing() {
        let dir = std::env::temp_dir().join(format!("rubblepile_notes_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let _ = std::fs::remove_file(dir.join(NOTES_FILE));
        let mut md = "# Report\n\n| a |\n".to_string();
        append_notes(&mut md, &dir);
        assert_eq!(md, "# Report\n\n| a |\n");
        let notes = "## Notes\n\n| item | paper | ours |\n| --- | --- | --- |\n| T_c3 | 2.40 h | 2.64 h |\n";
        std::fs::write(dir.join(NOTES_FILE), notes).unwrap();
        append_notes(&mut md, &dir);
        assert_eq!(md, format!("# Report\n\n| a |\n\n{notes}\n"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The tally is counted from the table, whatever a hand-typed list would say: a row's verdict is its fifth
    /// cell's first word (bold or not), rows of other tables and text are not counted, an unknown verdict shows.
    #[test]
    fn the_tally_counts_the_verdict_column_of_numbered_rows() {
        let notes = format!(
            "| # | item | paper | ours | verdict | why |\n| --- | --- | --- | --- | --- | --- |\n\
             | 1 | a | 1 | 1 | reproduced | |\n| 2 | b | 1 | 2 | **partly** | x |\n| 3 | c | 1 | 9 | not | |\n\
             | 4 | d | 1 | `a\\|b` | not | |\n| 5 | e | 1 | 1 | partly (scaled) | |\n| 6 | f | 1 | 1 | reproducd | |\n\
             | model | T | x | y | z |\n| HCP | 2.4 | 1 | 2 | not |\n\nText.\n{TALLY_MARKER}\nAfter.\n"
        );
        let out = with_tally(&notes);
        let expected = "Reproduced: rows 1 (1). Partly: rows 2, 5 (2). Not: rows 3, 4 (2). Reproducd: rows 6 (1). \
                        Of 6 rows (counted from the table above by `rubblepile report`).";
        assert!(out.contains(&format!("Text.\n{expected}\nAfter.\n")), "{out}");
        assert!(!out.contains(TALLY_MARKER));
        assert_eq!(with_tally("no marker\n"), "no marker\n");
    }
}
