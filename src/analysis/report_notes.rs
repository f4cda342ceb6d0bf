//! The hand-written part of a generated report: `NOTES.md` in the report's output directory, appended verbatim
//! after the generated sections (the Richardson11 and Zhang17 reports), so that a regenerated `REPORT.md` keeps
//! the discussion that no run can produce.

use std::path::Path;

/// The notes file's name in a report's output directory.
pub const NOTES_FILE: &str = "NOTES.md";

/// Appends `dir/NOTES.md` to `md` verbatim after a blank line (and a final newline); nothing when the file is
/// absent or unreadable (a report without notes is still a report).
pub fn append_notes(md: &mut String, dir: &Path) {
    if let Ok(text) = std::fs::read_to_string(dir.join(NOTES_FILE)) {
        md.push('\n');
        md.push_str(&text);
        md.push('\n');
    }
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
}
