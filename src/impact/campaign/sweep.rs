//! `[sweep]` of a campaign file: any field of the file varied over a list or a grid of values; the runs are the
//! Cartesian product. Generic: the file is serialised to a TOML value, the path set, and the value read back through
//! the file's schema, so every field of `[impact]`, `[campaign]` and `[[projectile]]` (present or future) is covered
//! and a wrong path is refused with the valid names.

use toml::Value;

use super::CampaignFile;

/// One swept field: its dotted path (e.g. `impact.speed_km_s`, `projectile[0].radius_km`) and its values.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepAxis {
    /// The field's path in the campaign file.
    pub path: String,
    /// Its values, in order.
    pub values: Vec<Value>,
}

/// Most values one grid may give.
const MAX_GRID: usize = 100_000;

/// The grid's own axes by their short names.
fn canonical(path: &str) -> &str {
    match path {
        "target" => "campaign.targets",
        "projectile" => "campaign.projectiles",
        "angle" | "angle_deg" => "campaign.angles",
        "seed" => "campaign.seeds",
        p => p,
    }
}

/// A value as written in run names and `campaign.csv` (strings bare, numbers in their shortest form).
pub fn value_text(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Float(x) => format!("{x}"),
        other => other.to_string(),
    }
}

/// The axes of `[sweep]`, sorted by path: the product's order, the first path outermost. A key maps to a list of
/// values or to a grid `{ from, to, step }` / `{ from, to, count }`; a nested table without `from` is a path prefix
/// (`impact.f0 = [...]` inside `[sweep]`). Errors: `(field, message)`.
pub fn sweep_axes(table: &toml::Table) -> Result<Vec<SweepAxis>, (String, String)> {
    let mut axes = Vec::new();
    flatten(table, "", &mut axes)?;
    axes.sort_by(|a, b| a.path.cmp(&b.path));
    if let Some(w) = axes.windows(2).find(|w| w[0].path == w[1].path) {
        return Err((
            format!("sweep.\"{}\"", w[0].path),
            "is swept twice (under two names)".into(),
        ));
    }
    Ok(axes)
}

fn flatten(table: &toml::Table, prefix: &str, axes: &mut Vec<SweepAxis>) -> Result<(), (String, String)> {
    for (key, v) in table {
        let path = if prefix.is_empty() {
            key.clone()
        } else {
            format!("{prefix}.{key}")
        };
        let field = format!("sweep.\"{path}\"");
        let values = match v {
            Value::Array(list) => list.clone(),
            Value::Table(t) if t.contains_key("from") => grid(t).map_err(|m| (field.clone(), m))?,
            Value::Table(t) => {
                flatten(t, &path, axes)?;
                continue;
            }
            other => {
                return Err((
                    field,
                    format!(
                        "expected a list of values or a grid {{ from, to, step }} / {{ from, to, count }}, got {other}"
                    ),
                ));
            }
        };
        if values.is_empty() {
            return Err((field, "must list at least one value, got []".into()));
        }
        if let Some(k) = (1..values.len()).find(|&k| values[..k].contains(&values[k])) {
            return Err((field, format!("{} is listed twice", values[k])));
        }
        let path = canonical(&path).to_string();
        if path == "campaign.out" || path == "campaign.parallel" {
            return Err((
                field,
                "not a field of a run: the campaign has one directory and one pool".into(),
            ));
        }
        axes.push(SweepAxis { path, values });
    }
    Ok(())
}

/// The values of a grid table: `from`, `from + step`, … up to `to` (inclusive, within 1e-9 of a step), or `count`
/// values evenly from `from` to `to`; integers when `from`, `to` and `step` are.
fn grid(t: &toml::Table) -> Result<Vec<Value>, String> {
    if let Some(k) = t
        .keys()
        .find(|k| !["from", "to", "step", "count"].contains(&k.as_str()))
    {
        return Err(format!(
            "unknown key `{k}` in a grid: expected from, to and one of step, count"
        ));
    }
    let num = |k: &str| match t.get(k) {
        Some(Value::Integer(i)) => Ok(*i as f64),
        Some(Value::Float(x)) if x.is_finite() => Ok(*x),
        None => Err(format!("{k}: missing (a grid has from, to and one of step, count)")),
        Some(o) => Err(format!("{k}: expected a finite number, got {o}")),
    };
    let (from, to) = (num("from")?, num("to")?);
    let int = |k: &str| matches!(t.get(k), Some(Value::Integer(_)));
    // 12 significant digits: 0.1 + 2 × 0.1 is 0.3, not 0.30000000000000004
    let round = |x: f64| format!("{x:.11e}").parse::<f64>().unwrap_or(x);
    let (xs, integers): (Vec<f64>, bool) = match (t.get("step"), t.get("count")) {
        (Some(_), None) => {
            let step = num("step")?;
            let n = (to - from) / step;
            if step == 0.0 || n < -1e-9 || !n.is_finite() {
                return Err(format!(
                    "step: must be non-zero and lead from {from} to {to}, got {step}"
                ));
            }
            if n + 1.0 > MAX_GRID as f64 {
                return Err(format!(
                    "step: at most {MAX_GRID} values, got {step} from {from} to {to}"
                ));
            }
            let n = (n + 1e-9).floor() as usize + 1;
            let xs = (0..n).map(|k| round(from + k as f64 * step)).collect();
            (xs, int("from") && int("to") && int("step"))
        }
        (None, Some(Value::Integer(c))) if (1..=MAX_GRID as i64).contains(c) && (*c > 1 || from == to) => {
            let c = *c as usize;
            let xs: Vec<f64> = (0..c)
                .map(|k| round(from + (to - from) * k as f64 / (c.max(2) - 1) as f64))
                .collect();
            let integral = int("from") && int("to") && xs.iter().all(|x| x.fract() == 0.0);
            (xs, integral)
        }
        (None, Some(c)) => {
            return Err(format!(
                "count: expected an integer from 2 to {MAX_GRID} (1 when from = to), got {c}"
            ));
        }
        _ => return Err("give exactly one of `step` and `count`".into()),
    };
    Ok(xs
        .into_iter()
        .map(|x| {
            if integers {
                Value::Integer(x as i64)
            } else {
                Value::Float(x)
            }
        })
        .collect())
}

/// `file` (its `[sweep]` aside) with each `(path, value)` set; a single value set into a list field makes a list of
/// one (`campaign.angles`). Errors `(field, message)` name the path and, for an unknown name, the valid ones.
pub fn with_overrides(file: &CampaignFile, overrides: &[(String, Value)]) -> Result<CampaignFile, (String, String)> {
    let mut base = file.clone();
    base.sweep.clear();
    let mut root = Value::try_from(&base).map_err(|e| ("sweep".to_string(), super::one_line(&e.to_string())))?;
    let mut out = base;
    for (path, value) in overrides {
        let field = format!("sweep.\"{path}\"");
        set(&mut root, path, value.clone()).map_err(|m| (field.clone(), m))?;
        out = root.clone().try_into::<CampaignFile>().map_err(|e| {
            (
                field.clone(),
                format!("not a valid field or value: {}", super::one_line(e.message())),
            )
        })?;
    }
    Ok(out)
}

/// Sets `path` (`a.b[2].c`) in `root`, creating missing tables.
fn set(root: &mut Value, path: &str, value: Value) -> Result<(), String> {
    let segments: Vec<&str> = path.split('.').collect();
    let mut at = root;
    for (k, seg) in segments.iter().enumerate() {
        let (name, index) = match seg.split_once('[') {
            Some((n, rest)) => {
                let i = rest
                    .strip_suffix(']')
                    .and_then(|i| i.parse::<usize>().ok())
                    .ok_or_else(|| format!("`{seg}`: expected name[index]"))?;
                (n, Some(i))
            }
            None => (*seg, None),
        };
        if name.is_empty() {
            return Err("empty name in the path".into());
        }
        let last = k + 1 == segments.len();
        let table = at
            .as_table_mut()
            .ok_or_else(|| format!("`{}` is not a table", segments[..k].join(".")))?;
        if last && index.is_none() {
            let value = match (table.get(name), value) {
                (Some(Value::Array(_)), v @ Value::Array(_)) => v,
                (Some(Value::Array(_)), v) => Value::Array(vec![v]),
                (_, v) => v,
            };
            table.insert(name.to_string(), value);
            return Ok(());
        }
        let entry = table
            .entry(name.to_string())
            .or_insert_with(|| Value::Table(Default::default()));
        at = match index {
            None => entry,
            Some(i) => {
                let list = entry.as_array_mut().ok_or_else(|| format!("`{name}` is not a list"))?;
                let len = list.len();
                list.get_mut(i)
                    .ok_or_else(|| format!("`{name}` has {len} entries, so no [{i}]"))?
            }
        };
        if last {
            *at = value;
            return Ok(());
        }
    }
    Ok(())
}
