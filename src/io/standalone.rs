//! The scene copy a run keeps in its directory (`DIR/scene.toml`), made to stand alone: every input file the scene
//! names by a relative path is written there by its absolute path, so `render`, `export`, `analyze`, `check` and
//! `resume` read the same files whatever directory they are started from. Absolute paths rather than copies: a
//! particles or bodies file can hold millions of rows, and the copy would double the run's inputs on disk.
//!
//! Only the file fields are rewritten, on their own lines; comments and layout stay as written. A value the
//! line-wise rewrite cannot reach (an escaped string, an inline `scene = { … }` table) is caught by re-reading the
//! result, and then the whole scene is written anew from its parsed table (comments lost, values kept).

use std::path::Path;

/// The scene fields that name an input file, as `(table, key)`: resolved against the scene's directory when
/// relative (`scene.bodies_file` of the ellipsoids, `scene.particles_file` of the soft and hard spheres).
pub const INPUT_FILE_FIELDS: [(&str, &str); 2] = [("scene", "bodies_file"), ("scene", "particles_file")];

/// `text` (a scene read from a file in `base_dir`) with every relative input file of [`INPUT_FILE_FIELDS`] replaced
/// by its absolute path (`base_dir` joined with it, made absolute against the current directory). A text with no
/// relative input file, or one that is not TOML, is returned as it is.
pub fn with_absolute_inputs(text: &str, base_dir: &Path) -> String {
    let Ok(mut table) = text.parse::<toml::Table>() else {
        return text.to_string();
    };
    let mut edited = text.to_string();
    let mut changed = false;
    for (section, key) in INPUT_FILE_FIELDS {
        let Some(rel) = table.get(section).and_then(|s| s.get(key)).and_then(|v| v.as_str()) else {
            continue;
        };
        if Path::new(rel).is_absolute() {
            continue;
        }
        let Ok(abs) = std::path::absolute(base_dir.join(rel)) else {
            continue;
        };
        let abs = abs.display().to_string();
        edited = replace_value_line(&edited, key, rel, &abs);
        if let Some(s) = table.get_mut(section).and_then(|s| s.as_table_mut()) {
            s.insert(key.to_string(), toml::Value::String(abs));
        }
        changed = true;
    }
    if !changed {
        return text.to_string();
    }
    match edited.parse::<toml::Table>() {
        Ok(t) if t == table => edited,
        // The line-wise edit missed (or hit something else): the parsed table, written anew, is exact.
        _ => format!(
            "# scene written anew by rubblepile with absolute input paths (its comments are in the original)\n{}",
            toml::to_string(&table).unwrap_or(edited)
        ),
    }
}

/// `text` with the quoted value `rel` on the line that sets `key` (`key = "rel"` or `key = 'rel'`) replaced by the
/// TOML string of `abs`. Lines are kept as they are otherwise; the caller checks the result by re-parsing it.
fn replace_value_line(text: &str, key: &str, rel: &str, abs: &str) -> String {
    let quoted = toml::Value::String(abs.to_string()).to_string();
    let mut out = String::with_capacity(text.len() + abs.len());
    let mut done = false;
    for line in text.split_inclusive('\n') {
        let sets_key = line
            .trim_start()
            .strip_prefix(key)
            .is_some_and(|rest| rest.trim_start().starts_with('='));
        if !done && sets_key {
            for literal in [format!("\"{rel}\""), format!("'{rel}'")] {
                if let Some(at) = line.find(&literal) {
                    out.push_str(&line[..at]);
                    out.push_str(&quoted);
                    out.push_str(&line[at + literal.len()..]);
                    done = true;
                    break;
                }
            }
            if done {
                continue;
            }
        }
        out.push_str(line);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_particles_file_becomes_absolute_and_comments_stay() {
        let text = "# a comment\n[scene]\nkind = \"soft-spheres\"\nparticles_file = \"in/p.csv\"   # the grains\n";
        let out = with_absolute_inputs(text, Path::new("/data/scenes"));
        assert_eq!(
            out,
            "# a comment\n[scene]\nkind = \"soft-spheres\"\nparticles_file = \"/data/scenes/in/p.csv\"   # the grains\n"
        );
    }

    #[test]
    fn absolute_paths_and_scenes_without_files_are_untouched() {
        let abs = "[scene]\nbodies_file = '/x/b.csv'\n";
        assert_eq!(with_absolute_inputs(abs, Path::new("/data")), abs);
        let none = "[scene]\nt_end = 1.0\n";
        assert_eq!(with_absolute_inputs(none, Path::new("/data")), none);
    }

    #[test]
    fn an_inline_scene_table_is_written_anew_with_the_absolute_path() {
        let text = "scene = { bodies_file = \"b.csv\", t_end = 2.0 }\n";
        let out = with_absolute_inputs(text, Path::new("/data"));
        let t: toml::Table = out.parse().unwrap();
        assert_eq!(t["scene"]["bodies_file"].as_str(), Some("/data/b.csv"));
        assert_eq!(t["scene"]["t_end"].as_float(), Some(2.0));
    }
}
