//! The field reference of the scene files: one [`FieldDoc`] row per key a scene parser accepts (its unit, default,
//! allowed range and meaning), the text `rubblepile check --explain` prints from them ([`explain_text`]), and the
//! [`Validator`] check that reads a row's bounds ([`Validator::within`]), so that where a field's range is a plain
//! interval the validator enforces exactly what the reference prints. The rows are written on the serde structs'
//! fields and collected by `#[derive(SceneFields)]` (the `scene_derive` crate), which refuses a field without one.

use crate::io::scene_file::{MIN_MEANINGFUL, SceneError, Validator, fmt_num};

/// The allowed values of a field.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Range {
    /// A positive physical size: finite and at least [`MIN_MEANINGFUL`] ([`Validator::positive`]).
    Positive,
    /// Finite and ≥ 0 ([`Validator::non_negative`]).
    NonNegative,
    /// A finite number in an interval; an open end excludes its value.
    Interval {
        /// Lower end.
        lo: f64,
        /// Whether `lo` itself is allowed.
        lo_closed: bool,
        /// Upper end.
        hi: f64,
        /// Whether `hi` itself is allowed.
        hi_closed: bool,
    },
    /// A rule in words (it depends on other fields, or is not a number): checked by the parser's own code.
    Rule(&'static str),
}

impl Range {
    /// The closed interval `[lo, hi]`.
    pub const fn closed(lo: f64, hi: f64) -> Range {
        Range::Interval {
            lo,
            lo_closed: true,
            hi,
            hi_closed: true,
        }
    }

    /// The half-open interval `(lo, hi]`.
    pub const fn open_closed(lo: f64, hi: f64) -> Range {
        Range::Interval {
            lo,
            lo_closed: false,
            hi,
            hi_closed: true,
        }
    }

    /// The open interval `(lo, hi)`.
    pub const fn open(lo: f64, hi: f64) -> Range {
        Range::Interval {
            lo,
            lo_closed: false,
            hi,
            hi_closed: false,
        }
    }

    /// The half-open interval `[lo, hi)`.
    pub const fn closed_open(lo: f64, hi: f64) -> Range {
        Range::Interval {
            lo,
            lo_closed: true,
            hi,
            hi_closed: false,
        }
    }

    /// Whether `x` lies in the range (a [`Range::Rule`] admits every finite number: its own code decides).
    pub fn contains(&self, x: f64) -> bool {
        match *self {
            Range::Positive => x.is_finite() && x >= MIN_MEANINGFUL,
            Range::NonNegative => x.is_finite() && x >= 0.0,
            Range::Interval {
                lo,
                lo_closed,
                hi,
                hi_closed,
            } => {
                x.is_finite()
                    && (if lo_closed { x >= lo } else { x > lo })
                    && (if hi_closed { x <= hi } else { x < hi })
            }
            Range::Rule(_) => x.is_finite(),
        }
    }
}

impl std::fmt::Display for Range {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Range::Positive => write!(f, ">= {MIN_MEANINGFUL:e}, finite"),
            Range::NonNegative => write!(f, ">= 0, finite"),
            Range::Interval {
                lo,
                lo_closed,
                hi,
                hi_closed,
            } => write!(
                f,
                "{}{}, {}{}",
                if lo_closed { '[' } else { '(' },
                fmt_num(lo),
                fmt_num(hi),
                if hi_closed { ']' } else { ')' }
            ),
            Range::Rule(words) => f.write_str(words),
        }
    }
}

/// One key of a scene file: `key` is its dotted path with tables of arrays unindexed (`particle.radius` for every
/// `[[particle]]` table's `radius`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldDoc {
    /// Dotted path, e.g. `material.k_n`.
    pub key: &'static str,
    /// SI unit (`-` for a dimensionless number, `text`, `bool`, `count` for the others).
    pub unit: &'static str,
    /// Default when the key is absent, or `required`.
    pub default: &'static str,
    /// Allowed values.
    pub range: Range,
    /// What it is, in one line.
    pub meaning: &'static str,
}

/// A table of a scene file (`[scene]`, `[physics.gravity]`, `[[particle]]`, …) and what it is for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableDoc {
    /// Dotted path of the table, e.g. `physics.gravity`.
    pub key: &'static str,
    /// Whether it is an array of tables (`[[particle]]`).
    pub array: bool,
    /// What it is for, and what its absence means.
    pub meaning: &'static str,
}

/// The rows of a scene struct, written on its fields and collected by `#[derive(scene_derive::SceneFields)]`.
pub trait SceneFields {
    /// Dotted path of the table the struct is read from (`` for the file's top level).
    const TABLE: &'static str;
    /// Appends the struct's value rows, then each sub-table's row and its own rows, in declaration order.
    fn collect(fields: &mut Vec<FieldDoc>, tables: &mut Vec<TableDoc>);
}

/// Whether two keys are equal: the derive's compile-time check that a sub-table's struct declares the path its
/// parent reads it under (`==` on `str` is not `const`).
pub const fn same_key(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// The whole reference of one engine's scene file.
#[derive(Debug, Clone)]
pub struct SceneReference {
    /// The `scene.kind` string.
    pub kind: &'static str,
    /// Its tables.
    pub tables: Vec<TableDoc>,
    /// Its keys, in the order they are printed.
    pub fields: Vec<FieldDoc>,
}

impl SceneReference {
    /// The reference of the file whose top-level struct is `T`.
    pub fn of<T: SceneFields>(kind: &'static str) -> SceneReference {
        let (mut fields, mut tables) = (Vec::new(), Vec::new());
        T::collect(&mut fields, &mut tables);
        SceneReference { kind, tables, fields }
    }

    /// The row of `key`, if there is one.
    pub fn field(&self, key: &str) -> Option<&FieldDoc> {
        self.fields.iter().find(|f| f.key == key)
    }
}

/// The table a key lives in (`physics.gravity` of `physics.gravity.G`; `` of a top-level key).
fn table_of(key: &str) -> &str {
    key.rsplit_once('.').map_or("", |(t, _)| t)
}

/// The reference as text: a heading per table (`[physics.gravity]`, `[[particle]]`) with its meaning, then one
/// line per key, `table.key  unit  default  range  meaning`, in aligned columns.
pub fn explain_text(reference: &SceneReference) -> String {
    let mut out = format!("# kind = \"{}\"\n", reference.kind);
    let width = |f: fn(&FieldDoc) -> String| reference.fields.iter().map(|r| f(r).chars().count()).max().unwrap_or(0);
    let w_key = width(|r| r.key.to_string()).max("field".len());
    let w_unit = width(|r| r.unit.to_string()).max("unit".len());
    let w_default = width(|r| r.default.to_string()).max("default".len());
    let w_range = width(|r| r.range.to_string()).max("range".len());
    let line = |key: &str, unit: &str, default: &str, range: &str, meaning: &str| {
        let pad = |s: &str, w: usize| format!("{s}{}", " ".repeat(w.saturating_sub(s.chars().count())));
        format!(
            "{}  {}  {}  {}  {meaning}\n",
            pad(key, w_key),
            pad(unit, w_unit),
            pad(default, w_default),
            pad(range, w_range)
        )
    };
    out.push_str(&line("field", "unit", "default", "range", "meaning"));
    let mut current: Option<&str> = None;
    let mut headed: Vec<&str> = Vec::new();
    for f in &reference.fields {
        let table = table_of(f.key);
        if current != Some(table) {
            current = Some(table);
            // A table that holds only tables (`[physics]`) gets its heading before its first sub-table's.
            let mut chain = vec![table];
            while let Some((parent, _)) = chain[chain.len() - 1].rsplit_once('.') {
                chain.push(parent);
            }
            for t in chain.into_iter().rev().filter(|t| !t.is_empty()) {
                if !headed.contains(&t) {
                    headed.push(t);
                    out.push_str(&heading(reference, t));
                }
            }
        }
        out.push_str(&line(f.key, f.unit, f.default, &f.range.to_string(), f.meaning));
    }
    out
}

/// `\n[table]: meaning\n` (`[[table]]` for an array of tables).
fn heading(reference: &SceneReference, table: &str) -> String {
    let doc = reference.tables.iter().find(|t| t.key == table);
    let name = match doc {
        Some(t) if t.array => format!("[[{table}]]"),
        _ => format!("[{table}]"),
    };
    let meaning = doc.map_or(String::new(), |t| format!(": {}", t.meaning));
    format!("\n{name}{meaning}\n")
}

impl Validator<'_> {
    /// [`Validator::within`] for a field outside any array of tables: its label is the row's key.
    pub(crate) fn field(&self, doc: &FieldDoc, x: f64) -> Result<f64, SceneError> {
        self.within(doc, doc.key, x)
    }

    /// The value `x` of the field `label` (the row's key, indexed where it is in an array of tables, e.g.
    /// `particle[3].radius`) checked against the row's range: [`Validator::positive`] and
    /// [`Validator::non_negative`] for those ranges, the interval's ends for an interval (one line naming the field
    /// and the interval). A [`Range::Rule`] is checked by the parser's own code around this call: here only finite.
    pub(crate) fn within(&self, doc: &FieldDoc, label: &str, x: f64) -> Result<f64, SceneError> {
        match doc.range {
            Range::Positive => self.positive(label, x),
            Range::NonNegative => self.non_negative(label, x),
            range if range.contains(x) => Ok(x),
            Range::Rule(_) => Err(self.invalid(label, format!("must be finite, got {}", fmt_num(x)))),
            range => Err(self.invalid(label, format!("must be in {range}, got {}", fmt_num(x)))),
        }
    }
}
