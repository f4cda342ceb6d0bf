//! The old names of the granular scene files, rewritten to the one vocabulary (`granular::vocabulary`): both parsers
//! read a scene through [`migrate`] (one warning per old name), `rubblepile check --migrate` writes the migrated text
//! ([`command`]). Old → new: soft `[integrator]` → `[stepping]`, `[contact]` → `[material]`,
//! `wall.oscillation.frequency = f` (Hz) → `angular_frequency = 2π f` (rad/s), `amplitude = [ax, ay, az]` (m) →
//! `amplitude = |A|`, `direction = A/|A|`; hard `gravity.g` → `gravity.uniform` (m/s²), `wall.type` → `wall.kind`,
//! `wall.origin` → `wall.point` (plane) or `wall.centre`, a plane's `wall.axis` → `wall.normal`,
//! `wall.oscillation.omega` → `angular_frequency` (rad/s).
//!
//! The rewrite edits the TOML parse's spans, so comments, order and layout stay; a key is renamed only where its new
//! name is absent. Numbers are written shortest-round-trip, and `2π f` gives the bits the old law computed, so a
//! migrated scene runs bit for bit as before (an off-axis amplitude vector rounds its length and direction once).

use std::ops::Range;
use std::path::{Path, PathBuf};

use toml::Spanned;
use toml::de::{DeString, DeTable, DeValue};

/// One old name found, as it reads and as it is read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Rename {
    /// The old field (dotted, indexed in arrays of tables, e.g. `wall[0].type`), with its value where that changes.
    pub old: String,
    /// What it is read as.
    pub new: String,
}

/// A scene text with its old names replaced.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Migration {
    /// The text with every old name replaced; the input text unchanged when it has none (or is no granular scene,
    /// or no TOML).
    pub text: String,
    /// The old names found, in the order of the file's tables.
    pub renames: Vec<Rename>,
}

impl Migration {
    /// One warning line per old name, naming `file`, the old key and the new one.
    pub fn warnings(&self, file: &str) -> Vec<String> {
        self.renames
            .iter()
            .map(|r| {
                format!(
                    "{file}: {} is an old name, read as {} (`rubblepile check --migrate` rewrites the file)",
                    r.old, r.new
                )
            })
            .collect()
    }
}

/// The granular scene `text` with its old names replaced by the current ones (see the module's table). A text that
/// is not TOML or names no granular `scene.kind` comes back unchanged, with no renames.
pub fn migrate(text: &str) -> Migration {
    let unchanged = || Migration {
        text: text.to_string(),
        renames: Vec::new(),
    };
    let (Ok(doc), Ok(values)) = (DeTable::parse(text), text.parse::<toml::Table>()) else {
        return unchanged();
    };
    let soft = match values.get("scene").and_then(|s| s.get("kind")).and_then(|k| k.as_str()) {
        Some(crate::granular::vocabulary::SOFT_KIND) => true,
        Some(crate::granular::vocabulary::HARD_KIND) => false,
        _ => return unchanged(),
    };
    let mut edits = Edits {
        text,
        edits: Vec::new(),
        renames: Vec::new(),
    };
    let root = doc.get_ref();
    if soft {
        edits.rename(root, "", "integrator", "stepping");
        edits.rename(root, "", "contact", "material");
    } else if let Some(gravity) = table(root, "gravity") {
        edits.rename(gravity, "gravity.", "g", "uniform");
    }
    let walls = entry(root, "wall").and_then(|(_, v)| match v.get_ref() {
        DeValue::Array(a) => Some(a),
        _ => None,
    });
    let wall_values = values.get("wall").and_then(|w| w.as_array());
    for (k, wall) in walls.into_iter().flatten().enumerate() {
        let DeValue::Table(w) = wall.get_ref() else {
            continue;
        };
        let at = format!("wall[{k}].");
        let value = wall_values.and_then(|ws| ws.get(k));
        let osc = entry(w, "oscillation");
        if soft {
            if let Some((_, o)) = osc
                && let DeValue::Table(o_table) = o.get_ref()
            {
                let o_value = value.and_then(|v| v.get("oscillation"));
                edits.frequency(o_table, &format!("{at}oscillation."), o_value);
                edits.amplitude_vector(o_table, o, &format!("{at}oscillation."), o_value);
            }
        } else {
            let kind = value
                .and_then(|v| v.get("kind").or_else(|| v.get("type")))
                .and_then(|x| x.as_str());
            edits.rename(w, &at, "type", "kind");
            let plane = kind == Some("plane");
            edits.rename(w, &at, "origin", if plane { "point" } else { "centre" });
            if plane {
                edits.rename(w, &at, "axis", "normal");
            }
            if let Some((_, o)) = osc
                && let DeValue::Table(o_table) = o.get_ref()
            {
                edits.rename(o_table, &format!("{at}oscillation."), "omega", "angular_frequency");
            }
        }
    }
    edits.finish()
}

/// `rubblepile check --migrate SCENE [--out FILE] [--force]`: the scene migrated ([`migrate`]) to FILE (an existing
/// one only with `force`), to SCENE itself with `force` and no FILE, else to the output channel (`io::messages`);
/// files are written atomically, and each old name found is a `migrated: old -> new` warning line. Errors are one
/// line naming the file.
pub fn command(scene: &Path, out: Option<PathBuf>, force: bool) -> Result<(), String> {
    use crate::io::messages::{Channel, emit};
    use crate::io::safe_write::{describe, reason, write_atomic};
    let text = crate::io::scene_file::read_text_bounded(scene)
        .map_err(|e| format!("{}: cannot read: {}", scene.display(), reason(&e)))?;
    if DeTable::parse(&text).is_err() {
        return Err(format!(
            "{}: not TOML, nothing migrated (`rubblepile check` names the error)",
            scene.display()
        ));
    }
    let migration = migrate(&text);
    if let Some(file) = &out
        && !force
        && std::fs::symlink_metadata(file).is_ok()
    {
        return Err(format!("{}: exists; give --force to overwrite it", file.display()));
    }
    let target = out.or_else(|| force.then(|| scene.to_path_buf()));
    if let Some(target) = &target {
        write_atomic(target, &migration.text).map_err(|e| describe(target, &e))?;
    }
    for r in &migration.renames {
        emit(Channel::Warning, &format!("migrated: {} -> {}", r.old, r.new));
    }
    match target {
        Some(path) => emit(
            Channel::Out,
            &format!("wrote {} ({} old names)", path.display(), migration.renames.len()),
        ),
        None => migration.text.lines().for_each(|l| emit(Channel::Out, l)),
    }
    Ok(())
}

/// The entry `name` of table `t`: its key and value with their spans.
fn entry<'a, 'i>(t: &'a DeTable<'i>, name: &str) -> Option<(&'a Spanned<DeString<'i>>, &'a Spanned<DeValue<'i>>)> {
    t.iter().find(|(k, _)| k.get_ref().as_ref() == name)
}

/// The sub-table `name` of `t`.
fn table<'a, 'i>(t: &'a DeTable<'i>, name: &str) -> Option<&'a DeTable<'i>> {
    match entry(t, name)?.1.get_ref() {
        DeValue::Table(inner) => Some(inner),
        _ => None,
    }
}

/// A float as TOML writes it, in the shortest form that reads back as the same `f64`.
fn toml_float(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf".into() } else { "-inf".into() }
    } else {
        format!("{x:?}")
    }
}

/// A number of a TOML value (a float, or an integer as `f64`).
fn number(v: Option<&toml::Value>) -> Option<f64> {
    let v = v?;
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

/// The text edits of a migration and the renames they make.
struct Edits<'t> {
    text: &'t str,
    edits: Vec<(Range<usize>, String)>,
    renames: Vec<Rename>,
}

impl Edits<'_> {
    /// Renames the key `old` of table `t` (fields named `{at}old`) to `new`, unless `new` is there already.
    fn rename(&mut self, t: &DeTable, at: &str, old: &str, new: &str) {
        let Some((key, _)) = entry(t, old) else {
            return;
        };
        if entry(t, new).is_some() {
            return;
        }
        self.edits.push((key.span(), new.to_string()));
        let show = |k: &str| {
            if at.is_empty() {
                format!("[{k}]")
            } else {
                format!("{at}{k}")
            }
        };
        self.renames.push(Rename {
            old: show(old),
            new: show(new),
        });
    }

    /// `frequency = f` (Hz) of the oscillation table `o` → `angular_frequency = 2π f` (rad/s): the product the old
    /// oscillation law formed, so the new law's `ω t` is the old `2π f t` to the bit.
    fn frequency(&mut self, o: &DeTable, at: &str, value: Option<&toml::Value>) {
        let Some((key, val)) = entry(o, "frequency") else {
            return;
        };
        if entry(o, "angular_frequency").is_some() {
            return;
        }
        self.edits.push((key.span(), "angular_frequency".into()));
        let old = format!("{at}frequency");
        let Some(f) = number(value.and_then(|v| v.get("frequency"))) else {
            // Not a number: the key alone is renamed and the parser names the value.
            self.renames.push(Rename {
                old,
                new: format!("{at}angular_frequency"),
            });
            return;
        };
        let omega = std::f64::consts::TAU * f;
        self.edits.push((val.span(), toml_float(omega)));
        self.renames.push(Rename {
            old: format!("{old} = {} Hz", toml_float(f)),
            new: format!("{at}angular_frequency = {} rad/s (2 pi f)", toml_float(omega)),
        });
    }

    /// A vector `amplitude = [ax, ay, az]` (m) of the oscillation table `o` (its value `o_span`) → `amplitude = |A|`
    /// and `direction = A/|A|`; along an axis both are exact (`|A|` the one component's size, the direction a signed
    /// unit vector), so the law's `d̂ (|A| s)` is the old `A s` to the bit.
    fn amplitude_vector(&mut self, o: &DeTable, o_span: &Spanned<DeValue>, at: &str, value: Option<&toml::Value>) {
        let Some((key, val)) = entry(o, "amplitude") else {
            return;
        };
        let Some(a) = value.and_then(|v| v.get("amplitude")).and_then(|a| a.as_array()) else {
            return;
        };
        let components: Vec<f64> = a.iter().filter_map(|x| number(Some(x))).collect();
        if components.len() != 3 || a.len() != 3 || entry(o, "direction").is_some() {
            return;
        }
        let nonzero: Vec<usize> = (0..3).filter(|&i| components[i] != 0.0).collect();
        let (size, direction) = match nonzero[..] {
            [] => (0.0, [0.0, 0.0, 1.0]),
            [i] => {
                let mut d = [0.0; 3];
                d[i] = components[i].signum();
                (components[i].abs(), d)
            }
            _ => {
                let v = crate::math::Vec3::from([components[0], components[1], components[2]]);
                let n = v.norm();
                (n, [v.x / n, v.y / n, v.z / n])
            }
        };
        let direction_text = format!(
            "[{}, {}, {}]",
            toml_float(direction[0]),
            toml_float(direction[1]),
            toml_float(direction[2])
        );
        self.edits.push((val.span(), toml_float(size)));
        let inline = self.text[o_span.span()].trim_start().starts_with('{');
        if inline {
            self.edits.push((
                val.span().end..val.span().end,
                format!(", direction = {direction_text}"),
            ));
        } else {
            // A `[wall.oscillation]` table or dotted keys: a line of its own after the amplitude's, with the
            // amplitude key's prefix (indentation, `oscillation.`).
            let line_start = self.text[..key.span().start].rfind('\n').map_or(0, |p| p + 1);
            let line_end = self.text[val.span().end..]
                .find('\n')
                .map_or(self.text.len(), |p| val.span().end + p);
            let prefix = &self.text[line_start..key.span().start];
            self.edits
                .push((line_end..line_end, format!("\n{prefix}direction = {direction_text}")));
        }
        self.renames.push(Rename {
            old: format!(
                "{at}amplitude = [{}, {}, {}] (a vector)",
                toml_float(components[0]),
                toml_float(components[1]),
                toml_float(components[2])
            ),
            new: format!(
                "{at}amplitude = {} m and {at}direction = {direction_text}",
                toml_float(size)
            ),
        });
    }

    /// The text with every edit made (last first, so the spans stay valid), and the renames. A line whose edits
    /// change its length keeps its trailing comment in its column where the spaces before it allow.
    fn finish(mut self) -> Migration {
        let text = self.text;
        // Per edited line (its start): the change of length and where its last edit ends.
        let mut lines: std::collections::BTreeMap<usize, (isize, usize)> = std::collections::BTreeMap::new();
        for (range, replacement) in self.edits.iter().filter(|(_, r)| !r.contains('\n')) {
            let start = text[..range.start].rfind('\n').map_or(0, |p| p + 1);
            let line = lines.entry(start).or_insert((0, range.end));
            line.0 += replacement.len() as isize - range.len() as isize;
            line.1 = line.1.max(range.end);
        }
        for (_, (delta, last)) in lines {
            let end = text[last..].find('\n').map_or(text.len(), |p| last + p);
            let rest = &text[last..end];
            let Some(hash) = rest.find('#') else { continue };
            if delta == 0 || rest[..hash].contains(['"', '\'']) {
                continue;
            }
            let spaces = rest[..hash].len() - rest[..hash].trim_end_matches(' ').len();
            let at = last + hash;
            if delta > 0 {
                let cut = (delta as usize).min(spaces.saturating_sub(1));
                self.edits.push((at - cut..at, String::new()));
            } else if spaces > 0 {
                self.edits.push((at..at, " ".repeat(delta.unsigned_abs())));
            }
        }
        self.edits.sort_by_key(|(r, _)| (r.start, r.end));
        let mut text = text.to_string();
        for (range, replacement) in self.edits.iter().rev() {
            text.replace_range(range.clone(), replacement);
        }
        Migration {
            text,
            renames: self.renames,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const OLD_SOFT: &str = r#"# a comment that stays
[scene]
kind = "soft-spheres"
t_end = 1.0

[integrator]   # the step
dt = 1e-3

[contact]
k_n = 1e6

[output]
every = 0.1

[[wall]]
kind = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
oscillation = { amplitude = [0.0, 0.0, -0.01], frequency = 5.0 }   # m, Hz

[[wall]]
kind = "sphere"
centre = [0.0, 0.0, 0.0]
radius = 5.0
[wall.oscillation]
amplitude = [0.3, 0.4, 0.0]   # m
frequency = 2
"#;

    const OLD_HARD: &str = r#"[scene]
kind = "hard-spheres"
t_end = 1.0
[stepping]
dt = 1e-3
[gravity]
g = [0.0, 0.0, -9.81]   # m/s²
[output]
every = 0.1
[[wall]]
type = "plane"
origin = [0.0, 0.0, 0.0]
axis = [0.0, 0.0, 1.0]
oscillation = { amplitude = 0.01, omega = 30.0, phase = 0.0 }
[[wall]]
type = "cylinder"
origin = [0.0, 0.0, 0.5]
axis = [0.0, 1.0, 0.0]
radius = 0.4
"#;

    /// The soft-sphere old names become the new ones in place; comments and layout stay; the frequency becomes
    /// `2π f` to the bit, an axis-aligned amplitude splits exactly, and a second migration changes nothing.
    #[test]
    fn soft_old_names_are_rewritten_in_place() {
        let m = migrate(OLD_SOFT);
        let t = &m.text;
        assert!(t.starts_with("# a comment that stays\n"), "{t}");
        assert!(
            t.contains("[stepping]     # the step\ndt = 1e-3\n") && t.contains("[material]\nk_n = 1e6\n"),
            "{t}"
        );
        let omega: f64 = std::f64::consts::TAU * 5.0;
        assert!(
            t.contains(&format!(
                "oscillation = {{ amplitude = 0.01, direction = [0.0, 0.0, -1.0], angular_frequency = {omega:?} }} # m, Hz"
            )),
            "{t}"
        );
        // The comment keeps its column.
        let line = t.lines().find(|l| l.starts_with("amplitude = 0.5 ")).unwrap();
        assert_eq!(line.find('#'), "amplitude = [0.3, 0.4, 0.0]   # m".find('#'), "{t}");
        assert!(t.contains("# m\ndirection = [0.6, 0.8, 0.0]\n"), "{t}");
        let table: toml::Table = t.parse().unwrap();
        let w = &table["wall"][1]["oscillation"];
        assert_eq!(w["angular_frequency"].as_float(), Some(std::f64::consts::TAU * 2.0));
        assert_eq!(m.renames.len(), 6, "{:?}", m.renames);
        assert!(m.warnings("s.toml")[0].contains("[integrator] is an old name, read as [stepping]"));
        assert_eq!(
            migrate(t),
            Migration {
                text: t.clone(),
                renames: vec![]
            }
        );
    }

    /// The hard-sphere old names: gravity's `g`, a wall's `type`, `origin` (a plane's point, the others' centre),
    /// a plane's `axis` (its normal) and `omega`.
    #[test]
    fn hard_old_names_are_rewritten_in_place() {
        let m = migrate(OLD_HARD);
        let t = &m.text;
        assert!(t.contains("uniform = [0.0, 0.0, -9.81] # m/s²"), "{t}");
        assert!(
            t.contains("kind = \"plane\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n"),
            "{t}"
        );
        assert!(
            t.contains("{ amplitude = 0.01, angular_frequency = 30.0, phase = 0.0 }"),
            "{t}"
        );
        assert!(
            t.contains("kind = \"cylinder\"\ncentre = [0.0, 0.0, 0.5]\naxis = [0.0, 1.0, 0.0]\n"),
            "{t}"
        );
        let old: Vec<&str> = m.renames.iter().map(|r| r.old.as_str()).collect();
        assert_eq!(
            old,
            [
                "gravity.g",
                "wall[0].type",
                "wall[0].origin",
                "wall[0].axis",
                "wall[0].oscillation.omega",
                "wall[1].type",
                "wall[1].origin"
            ]
        );
        assert!(migrate(t).renames.is_empty());
    }

    /// A key whose new name is given too is left for the parser; a text that is no TOML or no granular scene is
    /// returned as it is.
    #[test]
    fn nothing_is_renamed_onto_a_given_key_or_outside_granular_scenes() {
        let both = OLD_HARD.replace("g = [", "uniform = [0.0, 0.0, -1.0]\ng = [");
        assert!(migrate(&both).text.contains("\ng = ["));
        for text in [
            "[scene]\nkind = \"ellipsoids\"\n[integrator]\nrtol = 1e-9\n",
            "not = = toml",
        ] {
            let m = migrate(text);
            assert_eq!((m.text.as_str(), m.renames.len()), (text, 0));
        }
    }
}
