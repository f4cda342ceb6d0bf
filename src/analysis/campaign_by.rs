//! A campaign's outcomes against one field of its index (`analyze-campaign --by FIELD`): the analysed runs grouped by
//! the field's value and by every other varying field but the seed, so each row's runs differ only in their seed;
//! per row the mean, standard error and individual values of each outcome (`analysis/campaign_by_<FIELD>.csv`).

use std::path::{Path, PathBuf};

use crate::analysis::run_analysis::{AnalysisError, CampaignAnalysis, CampaignRun};
use crate::impact::campaign::{CAMPAIGN_COLUMNS, CAMPAIGN_CSV};

/// How an outcome is read from a run.
pub type Outcome = fn(&CampaignRun) -> Option<f64>;

/// The outcomes tabulated, with how each is read from a run.
pub const BY_METRICS: [(&str, Outcome); 7] = [
    ("largest_remnant_fraction", |r| r.largest_remnant_fraction),
    ("bound_mass_fraction", |r| Some(r.bound_mass_fraction)),
    ("fragments", |r| Some(r.fragments as f64)),
    ("escaping", |r| Some(r.escaping as f64)),
    ("f_ke", |r| Some(r.f_ke)),
    ("ejection_speed_median_m_s", |r| Some(r.ejection_speed_median)),
    ("q_erg_per_g", |r| Some(r.q_erg_per_g)),
];

/// Whether a column of the index is not one of a run's inputs (its name, and the outcome columns of
/// [`CAMPAIGN_COLUMNS`] from `status` on), or groups runs that differ only in their seed (`seed`, `q_erg_per_g`).
fn is_not_key(h: &str) -> bool {
    let outcomes = CAMPAIGN_COLUMNS
        .iter()
        .position(|c| *c == "status")
        .unwrap_or(CAMPAIGN_COLUMNS.len());
    matches!(h, "run" | "seed" | "campaign.seeds" | "q_erg_per_g") || CAMPAIGN_COLUMNS[outcomes..].contains(&h)
}

/// One outcome over one row's runs.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ByStat {
    /// The outcome ([`BY_METRICS`]).
    pub metric: String,
    /// Its value in each run (those that have one).
    pub values: Vec<f64>,
    /// Their mean (NaN without values).
    pub mean: f64,
    /// Standard error of the mean, `s/√n` (NaN for fewer than two values).
    pub standard_error: f64,
}

impl ByStat {
    fn of(metric: &str, values: Vec<f64>) -> Self {
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        ByStat {
            metric: metric.to_string(),
            mean,
            standard_error: if values.len() > 1 { (var / n).sqrt() } else { f64::NAN },
            values,
        }
    }
}

/// One value of the field (with one value of each other varying field).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ByRow {
    /// The field's value as written in the index.
    pub value: String,
    /// It as a number, when it is one.
    pub x: Option<f64>,
    /// The values of [`ByTable::key_fields`].
    pub key: Vec<String>,
    /// The runs (differing only in their seed).
    pub runs: Vec<String>,
    /// One per [`BY_METRICS`].
    pub stats: Vec<ByStat>,
}

/// The outcomes against a field.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ByTable {
    /// The field (a column of `campaign.csv`).
    pub field: String,
    /// The other fields that vary among the runs (seed aside), which also split the rows.
    pub key_fields: Vec<String>,
    /// Rows sorted by the field's value, then by the key fields in turn ([`sort_rows`]).
    pub rows: Vec<ByRow>,
}

/// The column `requested` names (a column, `q`, `angle`, a swept path's short name or last segment), or, when
/// `None`, the campaign's one swept field if it has exactly one, else `q_erg_per_g`. Swept means a field of the
/// campaign file's `[sweep]` table (a column of `campaign.csv` after [`CAMPAIGN_COLUMNS`]), seeds aside; the
/// `[campaign]` lists (targets, projectiles, angles) are the grid, not a sweep.
fn choose(header: &[String], requested: Option<&str>) -> Result<String, AnalysisError> {
    let has = |c: &str| header.iter().any(|h| h == c);
    fn alias(c: &str) -> &str {
        match c {
            "q" | "Q" => "q_erg_per_g",
            "angle" | "campaign.angles" => "angle_deg",
            "campaign.targets" => "target",
            "campaign.projectiles" => "projectile",
            "campaign.seeds" => "seed",
            c => c,
        }
    }
    let swept: Vec<&str> = header[CAMPAIGN_COLUMNS.len().min(header.len())..]
        .iter()
        .map(|h| alias(h))
        .filter(|h| *h != "seed")
        .collect();
    let Some(req) = requested else {
        return Ok(match swept[..] {
            [one] => one.to_string(),
            _ => "q_erg_per_g".to_string(),
        });
    };
    let a = alias(req);
    if has(a) {
        return Ok(a.to_string());
    }
    let by_leaf: Vec<&String> = header[CAMPAIGN_COLUMNS.len().min(header.len())..]
        .iter()
        .filter(|h| h.rsplit('.').next() == Some(req))
        .collect();
    match by_leaf[..] {
        [one] => Ok(one.clone()),
        _ => {
            let valid: Vec<&str> = header
                .iter()
                .map(String::as_str)
                .filter(|h| !is_not_key(h) || ["seed", "q_erg_per_g"].contains(h))
                .filter(|h| !h.ends_with("_error") && !h.starts_with("campaign."))
                .collect();
            Err(AnalysisError::Request(format!(
                "--by: campaign.csv has no field `{req}`; expected one of {}",
                valid.join(", ")
            )))
        }
    }
}

/// Orders two cells: numerically when both parse as numbers, else as text (numbers first).
fn cell_order(a: &str, b: &str) -> std::cmp::Ordering {
    let number = |s: &str| s.parse::<f64>().ok().filter(|x| !x.is_nan());
    match (number(a), number(b)) {
        (Some(x), Some(y)) => x.total_cmp(&y),
        (Some(_), None) => std::cmp::Ordering::Less,
        (None, Some(_)) => std::cmp::Ordering::Greater,
        (None, None) => a.cmp(b),
    }
}

/// Sorts `rows` by the field's value, then by each key field in turn, each numerically where both cells are
/// numbers (5 before 20 before 50), else as text.
pub fn sort_rows(rows: &mut [ByRow]) {
    rows.sort_by(|a, b| {
        let keys = a.key.iter().zip(&b.key).map(|(x, y)| cell_order(x, y));
        std::iter::once(cell_order(&a.value, &b.value))
            .chain(keys)
            .find(|o| o.is_ne())
            .unwrap_or(std::cmp::Ordering::Equal)
    });
}

/// `dir/campaign.csv`: its header and rows.
fn read_index(dir: &Path) -> Result<(Vec<String>, Vec<Vec<String>>), AnalysisError> {
    let index = dir.join(CAMPAIGN_CSV);
    let err = |e: &dyn std::fmt::Display| AnalysisError::read(&index, e);
    let mut rdr = csv::Reader::from_path(&index).map_err(|e| err(&e))?;
    let header: Vec<String> = rdr.headers().map_err(|e| err(&e))?.iter().map(String::from).collect();
    let rows: Vec<Vec<String>> = rdr
        .records()
        .map(|r| r.map(|r| r.iter().map(String::from).collect()))
        .collect::<Result<_, _>>()
        .map_err(|e| err(&e))?;
    Ok((header, rows))
}

/// The column of `dir/campaign.csv` that `requested` names, or the default field for `None` (see [`choose`]);
/// an error naming `--by` and the valid fields when there is none (check it before a long analysis).
pub fn by_field_name(dir: &Path, requested: Option<&str>) -> Result<String, AnalysisError> {
    let (header, _) = read_index(dir)?;
    choose(&header, requested)
}

/// The table of `analysis`'s runs against `field` (see [`choose`] for `None`), from `dir/campaign.csv`.
pub fn by_field_table(dir: &Path, analysis: &CampaignAnalysis, field: Option<&str>) -> Result<ByTable, AnalysisError> {
    let (header, rows) = read_index(dir)?;
    let err = |e: &dyn std::fmt::Display| AnalysisError::read(&dir.join(CAMPAIGN_CSV), e);
    let field = choose(&header, field)?;
    let col = |c: &str| header.iter().position(|h| h == c);
    let (c_run, c_by) = (
        col("run").ok_or_else(|| err(&"no `run` column"))?,
        col(&field).unwrap_or(0),
    );
    let analysed: Vec<(&Vec<String>, &CampaignRun)> = analysis
        .runs
        .iter()
        .filter_map(|r| Some((rows.iter().find(|row| row[c_run] == r.run)?, r)))
        .collect();
    // the other inputs that vary among the analysed runs split the rows
    let key_cols: Vec<usize> = (0..header.len())
        .filter(|&c| c != c_by && !is_not_key(&header[c]) && !header[c].ends_with("_error"))
        .filter(|&c| !(field == "angle_deg" && header[c] == "campaign.angles"))
        .filter(|&c| analysed.iter().any(|(row, _)| row[c] != analysed[0].0[c]))
        .collect();
    let mut groups: Vec<(String, Vec<String>, Vec<&CampaignRun>)> = Vec::new();
    for (row, run) in &analysed {
        let key: Vec<String> = key_cols.iter().map(|&c| row[c].clone()).collect();
        let value = row[c_by].clone();
        match groups.iter_mut().find(|g| g.0 == value && g.1 == key) {
            Some(g) => g.2.push(run),
            None => groups.push((value, key, vec![run])),
        }
    }
    let mut table_rows: Vec<ByRow> = groups
        .into_iter()
        .map(|(value, key, runs)| ByRow {
            x: value.parse::<f64>().ok().filter(|x| x.is_finite()),
            stats: BY_METRICS
                .iter()
                .map(|(m, get)| ByStat::of(m, runs.iter().filter_map(|r| get(r)).collect()))
                .collect(),
            runs: runs.iter().map(|r| r.run.clone()).collect(),
            value,
            key,
        })
        .collect();
    sort_rows(&mut table_rows);
    Ok(ByTable {
        key_fields: key_cols.iter().map(|&c| header[c].clone()).collect(),
        field,
        rows: table_rows,
    })
}

impl ByTable {
    /// The file stem of the table and its figure: `campaign_by_<field>` (other characters than letters, digits, `_`,
    /// `-` as `_`).
    pub fn stem(&self) -> String {
        let f: String = self
            .field
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' })
            .collect();
        format!("campaign_by_{f}")
    }

    /// Writes `dir/analysis/<stem>.csv`: the field, the key fields, `runs`, then `<metric>_mean`, `<metric>_se` and
    /// `<metric>_values` (`;`-separated) per outcome. Returns its path.
    pub fn write_csv(&self, dir: &Path) -> Result<PathBuf, AnalysisError> {
        let path = dir.join("analysis").join(format!("{}.csv", self.stem()));
        let werr = |e: &dyn std::fmt::Display| AnalysisError::Write {
            path: path.clone(),
            reason: e.to_string(),
        };
        let mut w = csv::Writer::from_writer(Vec::new());
        let mut header: Vec<String> = vec![self.field.clone()];
        header.extend(self.key_fields.iter().cloned());
        header.push("runs".into());
        for (m, _) in BY_METRICS {
            header.extend([format!("{m}_mean"), format!("{m}_se"), format!("{m}_values")]);
        }
        w.write_record(&header).map_err(|e| werr(&e))?;
        let num = |x: f64| if x.is_finite() { format!("{x}") } else { String::new() };
        for r in &self.rows {
            let mut rec: Vec<String> = vec![r.value.clone()];
            rec.extend(r.key.iter().cloned());
            rec.push(r.runs.len().to_string());
            for s in &r.stats {
                let values: Vec<String> = s.values.iter().map(|v| format!("{v}")).collect();
                rec.extend([num(s.mean), num(s.standard_error), values.join(";")]);
            }
            w.write_record(&rec).map_err(|e| werr(&e))?;
        }
        let bytes = w.into_inner().map_err(|e| werr(&e))?;
        crate::io::safe_write::write_atomic(&path, bytes).map_err(|e| werr(&crate::io::safe_write::reason(&e)))?;
        Ok(path)
    }

    /// The table for a console: one line per row, `mean ± standard error (n runs)` of the largest remnant fraction,
    /// bound mass fraction and number of fragments (a count as its integer when the runs agree); Q to 4
    /// significant digits.
    pub fn lines(&self) -> Vec<String> {
        let mut head = vec![self.field.clone()];
        head.extend(self.key_fields.iter().cloned());
        let mut out = vec![format!(
            "{} | runs | largest remnant fraction | bound mass fraction | fragments",
            head.join(" | ")
        )];
        let pm = |s: &ByStat| {
            let counts = ["fragments", "escaping"].contains(&s.metric.as_str()) && !s.values.is_empty();
            match (counts, s.standard_error.is_finite()) {
                // a count: the integer when every run agrees, else mean ± se to a hundredth
                (true, _) if s.values.iter().all(|v| *v == s.values[0]) => format!("{}", s.values[0]),
                (true, true) => format!("{:.2} ± {:.2}", s.mean, s.standard_error),
                (false, true) => format!("{:.4} ± {:.4}", s.mean, s.standard_error),
                (_, false) => format!("{:.4}", s.mean),
            }
        };
        // Q to 4 significant digits (the CSV keeps every digit)
        let value = |field: &str, v: &str| match v.parse::<f64>() {
            Ok(x) if field == "q_erg_per_g" => format!("{x:.3e}"),
            _ => v.to_string(),
        };
        for r in &self.rows {
            let mut cells = vec![value(&self.field, &r.value)];
            cells.extend(r.key.iter().cloned());
            out.push(format!(
                "{} | {} | {} | {} | {}",
                cells.join(" | "),
                r.runs.len(),
                pm(&r.stats[0]),
                pm(&r.stats[1]),
                pm(&r.stats[2])
            ));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(swept: &[&str]) -> Vec<String> {
        CAMPAIGN_COLUMNS.iter().chain(swept).map(|s| s.to_string()).collect()
    }

    /// The default `--by` is the one field of `[sweep]` (seeds aside), whatever the `[campaign]` grid varies
    /// (several angles too), else Q.
    #[test]
    fn the_default_by_is_the_one_sweep_field() {
        assert_eq!(
            choose(&header(&["impact.speed_km_s"]), None).unwrap(),
            "impact.speed_km_s"
        );
        assert_eq!(
            choose(&header(&["campaign.seeds", "impact.speed_km_s"]), None).unwrap(),
            "impact.speed_km_s"
        );
        assert_eq!(choose(&header(&["campaign.angles"]), None).unwrap(), "angle_deg");
        assert_eq!(choose(&header(&[]), None).unwrap(), "q_erg_per_g");
        let two = header(&["impact.speed_km_s", "impact.t_end"]);
        assert_eq!(choose(&two, None).unwrap(), "q_erg_per_g");
    }

    fn row(value: &str, key: &[&str], fragments: &[f64]) -> ByRow {
        ByRow {
            value: value.into(),
            x: value.parse().ok(),
            key: key.iter().map(|k| k.to_string()).collect(),
            runs: fragments.iter().map(|f| format!("r{f}")).collect(),
            stats: BY_METRICS
                .iter()
                .map(|(m, _)| {
                    ByStat::of(
                        m,
                        if *m == "fragments" {
                            fragments.to_vec()
                        } else {
                            vec![0.5, 0.25]
                        },
                    )
                })
                .collect(),
        }
    }

    /// Rows go by the field's value, then by each key, numerically where the cells are numbers (text sorts 20
    /// before 5 before 50; numbers 5, 20, 50).
    #[test]
    fn rows_sort_numerically_by_value_then_keys() {
        let mut rows: Vec<ByRow> = [
            ("45", "50"),
            ("0", "20"),
            ("45", "5"),
            ("0", "5"),
            ("0", "50"),
            ("45", "20"),
        ]
        .iter()
        .map(|(a, s)| row(a, &[s, "N30_T4"], &[30.0]))
        .collect();
        sort_rows(&mut rows);
        let order: Vec<(&str, &str)> = rows.iter().map(|r| (r.value.as_str(), r.key[0].as_str())).collect();
        let mut want = order.clone();
        want.sort_by(|a, b| {
            let n = |s: &str| s.parse::<f64>().unwrap();
            n(a.0).total_cmp(&n(b.0)).then(n(a.1).total_cmp(&n(b.1)))
        });
        assert_eq!(order, want);
        assert_eq!(order[..3], [("0", "5"), ("0", "20"), ("0", "50")]);
        // text after numbers, text among itself as text
        let mut mixed = vec![
            row("b", &[], &[1.0]),
            row("10", &[], &[1.0]),
            row("a", &[], &[1.0]),
            row("9", &[], &[1.0]),
        ];
        sort_rows(&mut mixed);
        let values: Vec<&str> = mixed.iter().map(|r| r.value.as_str()).collect();
        assert_eq!(values, ["9", "10", "a", "b"]);
    }

    /// The console table prints Q to 4 significant digits and a count on which the runs agree as its integer (no
    /// "30.0000 ± 0.0000"); a count that differs keeps its mean ± standard error.
    #[test]
    fn console_rows_print_q_to_four_digits_and_counts_as_integers() {
        let q = 23912243924.102383_f64;
        let table = ByTable {
            field: "q_erg_per_g".into(),
            key_fields: vec![],
            rows: vec![
                row(&q.to_string(), &[], &[30.0, 30.0]),
                row("1494515245.256399", &[], &[29.0, 30.0]),
            ],
        };
        let lines = table.lines();
        let cells = |k: usize| lines[k].split(" | ").map(String::from).collect::<Vec<_>>();
        let first = cells(1);
        assert_eq!(first[0], "2.391e10");
        assert!((first[0].parse::<f64>().unwrap() / q - 1.0).abs() < 5e-4);
        assert_eq!(first[4], "30", "{}", lines[1]);
        assert_eq!(cells(2)[4], "29.50 ± 0.50", "{}", lines[2]);
        assert_eq!(first[3], "0.3750 ± 0.1250", "{}", lines[1]);
        // a fraction that is 1 in every run stays a fraction
        let mut whole = row("5", &[], &[30.0]);
        whole.stats[1] = ByStat::of("bound_mass_fraction", vec![1.0, 1.0]);
        let table = ByTable {
            field: "impact.speed_km_s".into(),
            key_fields: vec![],
            rows: vec![whole],
        };
        assert_eq!(
            table.lines()[1].split(" | ").nth(3),
            Some("1.0000 ± 0.0000"),
            "{:?}",
            table.lines()
        );
    }
}
