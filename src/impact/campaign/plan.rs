//! A campaign file resolved into its grid of impact runs, every value validated (errors name the field).

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use crate::ellipsoid::body::Body;
use crate::impact::pile::ProjectilePile;
use crate::impact::projectile::ProjectileSpec;
use crate::impact::run::{
    DEFAULT_BETA, DEFAULT_CONTACT_TIME, DEFAULT_EVERY, DEFAULT_F0, DEFAULT_T_END, ImpactConfig, ImpactError,
    ImpactPlan, default_rtol, default_snapshots, read_target,
};

use super::*;
use crate::io::scene_file::SceneError;

/// One grid point.
#[derive(Debug, Clone, PartialEq)]
pub struct GridPoint {
    /// Run name = directory name under the campaign directory, e.g. `N30_T4_P1_z45_s1`.
    pub name: String,
    /// The target file's stem.
    pub target: String,
    /// The projectile's id.
    pub projectile: String,
    /// ζ (degrees).
    pub angle_deg: f64,
    /// Seed.
    pub seed: u64,
    /// The impact.
    pub config: ImpactConfig,
    /// The impact set up in memory (what the run directory must hold).
    pub plan: ImpactPlan,
    /// The `[sweep]` values of this run: `(path, value as text)`, in the sweep's order (empty without a sweep).
    pub overrides: Vec<(String, String)>,
}

/// A validated campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct Campaign {
    /// How the campaign file is named in messages.
    pub name: String,
    /// The campaign directory (resolved).
    pub out: PathBuf,
    /// Runs at once.
    pub parallel: usize,
    /// The grid: targets (outermost), projectiles, angles, seeds (innermost).
    pub points: Vec<GridPoint>,
    /// The file as written.
    pub file: CampaignFile,
    /// The campaign file's absolute path, when it was read from a file (recorded in the campaign directory so
    /// that `rubblepile campaign merge DIR` finds the grid).
    pub source: Option<PathBuf>,
}

/// Reads and validates a campaign file; relative paths in it are resolved against its directory.
pub fn load_campaign(path: &Path) -> Result<Campaign, CampaignError> {
    let name = path.display().to_string();
    let text = crate::io::scene_file::read_text_bounded(path).map_err(|e| SceneError::Read {
        file: name.clone(),
        reason: e.to_string().split_whitespace().collect::<Vec<_>>().join(" "),
    })?;
    let base = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut campaign = parse_campaign(&text, &name, &base)?;
    campaign.source = std::fs::canonicalize(path).ok();
    Ok(campaign)
}

/// Parses and validates campaign text; `name` is used in messages, `base_dir` resolves relative paths.
pub fn parse_campaign(text: &str, name: &str, base_dir: &Path) -> Result<Campaign, CampaignError> {
    let file = parse_toml(text, name)?;
    if file.sweep.is_empty() {
        return resolve(file, name, base_dir);
    }
    resolve_sweep(file, name, base_dir)
}

/// The campaign of a file with a `[sweep]`: one resolved grid per combination of the swept values (the first path
/// outermost), concatenated, each run's name suffixed and its overrides recorded.
fn resolve_sweep(file: CampaignFile, name: &str, base_dir: &Path) -> Result<Campaign, CampaignError> {
    let invalid = |(field, message): (String, String)| invalid_in(name, field, message);
    let axes = sweep_axes(&file.sweep).map_err(invalid)?;
    let total: usize = axes.iter().map(|a| a.values.len()).product();
    let mut all: Option<Campaign> = None;
    let mut names = HashSet::new();
    for combo in 0..total {
        // odometer: the last axis varies fastest
        let mut rest = combo;
        let mut chosen = vec![0; axes.len()];
        for (k, a) in axes.iter().enumerate().rev() {
            chosen[k] = rest % a.values.len();
            rest /= a.values.len();
        }
        let overrides: Vec<(String, toml::Value)> = axes
            .iter()
            .zip(&chosen)
            .map(|(a, &i)| (a.path.clone(), a.values[i].clone()))
            .collect();
        let text: Vec<(String, String)> = overrides.iter().map(|(p, v)| (p.clone(), value_text(v))).collect();
        let with = with_overrides(&file, &overrides).map_err(invalid)?;
        let described = text
            .iter()
            .map(|(p, v)| format!("{p} = {v}"))
            .collect::<Vec<_>>()
            .join(", ");
        let mut c = resolve(with, name, base_dir).map_err(|e| match e {
            CampaignError::File(SceneError::Invalid { file, field, message }) => {
                invalid_in(&file, field, format!("{message} (with the sweep's {described})"))
            }
            other => other,
        })?;
        let suffix: String = text
            .iter()
            .filter(|(p, _)| !p.starts_with("campaign."))
            .map(|(p, v)| {
                let leaf = p.rsplit('.').next().unwrap_or(p);
                let clean = |s: &str| -> String {
                    s.chars()
                        .map(|ch| {
                            if ch.is_ascii_alphanumeric() || "_.-".contains(ch) {
                                ch
                            } else {
                                '-'
                            }
                        })
                        .collect()
                };
                format!("_{}{}", clean(leaf), clean(v))
            })
            .collect();
        for p in &mut c.points {
            p.name.push_str(&suffix);
            p.overrides = text.clone();
            if !names.insert(p.name.clone()) {
                return Err(invalid((
                    "sweep".into(),
                    format!(
                        "two runs would be named `{}`: make the swept values differ in their names",
                        p.name
                    ),
                )));
            }
        }
        match &mut all {
            None => all = Some(c),
            Some(a) => a.points.append(&mut c.points),
        }
    }
    let mut campaign = all.ok_or_else(|| invalid(("sweep".into(), "sweeps no value".into())))?;
    campaign.file = file;
    Ok(campaign)
}

/// `base.join(rel)` with `.` and `dir/..` removed lexically (for readable paths in messages and files).
fn join_clean(base: &Path, rel: &Path) -> PathBuf {
    use std::path::Component;
    let joined = base.join(rel);
    let mut out: Vec<Component> = Vec::new();
    for c in joined.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.last(), Some(Component::Normal(_))) => {
                out.pop();
            }
            c => out.push(c),
        }
    }
    if out.is_empty() {
        PathBuf::from(".")
    } else {
        out.iter().collect()
    }
}

/// The error of a value of the campaign file `file` out of range, naming its `field`.
fn invalid_in(file: &str, field: String, message: String) -> CampaignError {
    let file = file.to_string();
    CampaignError::File(SceneError::Invalid { file, field, message })
}

fn resolve(file: CampaignFile, name: &str, base_dir: &Path) -> Result<Campaign, CampaignError> {
    let invalid = |field: String, message: String| invalid_in(name, field, message);
    let c = &file.campaign;
    let imp = &file.impact;
    let listed = |empty: bool, field: &str, what: &str| match empty {
        true => Err(invalid(
            format!("campaign.{field}"),
            format!("must list at least one {what}, got []"),
        )),
        false => Ok(()),
    };
    let speed_ok = |field: String, v: f64| match v.is_finite() && v > 0.0 {
        true => Ok(v),
        false => Err(invalid(field, format!("must be > 0 km/s and finite, got {v}"))),
    };
    if c.out.as_os_str().is_empty() {
        return Err(invalid("campaign.out".into(), "must name a directory, got \"\"".into()));
    }
    let parallel = match c.parallel {
        Some(0) => return Err(invalid("campaign.parallel".into(), "must be at least 1, got 0".into())),
        Some(n) => n,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };

    // [impact]
    let t_end = imp.t_end.unwrap_or(DEFAULT_T_END);
    let speed_km_s = speed_ok("impact.speed_km_s".into(), imp.speed_km_s.unwrap_or(5.0))?;

    // [[projectile]]
    let mut custom: Vec<(String, ProjectileSpec)> = Vec::new();
    let mut piles: Vec<(String, ProjectilePile)> = Vec::new();
    for (k, p) in file.projectiles.iter().enumerate() {
        let field = |f: &str| format!("projectile[{k}].{f}");
        let id_ok = !p.id.is_empty()
            && p.id
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-');
        if !id_ok {
            return Err(invalid(
                field("id"),
                format!(
                    "need letters, digits, `_` or `-` (it names run directories), got {:?}",
                    p.id
                ),
            ));
        }
        if ProjectileSpec::preset(&p.id).is_some() || custom.iter().any(|(id, _)| *id == p.id) {
            return Err(invalid(
                field("id"),
                format!(
                    "`{}` is already a projectile (P1-P3 or an earlier [[projectile]])",
                    p.id
                ),
            ));
        }
        let speed = speed_ok(field("speed_km_s"), p.speed_km_s.unwrap_or(speed_km_s))?;
        let spec = match (p.radius_km, &p.projectile_pile) {
            (Some(r), None) if r.is_finite() && r > 0.0 && p.random_attitude.is_none() => {
                ProjectileSpec::custom(p.id.clone(), r * 1e3, speed * 1e3)
            }
            (Some(r), None) if !(r.is_finite() && r > 0.0) => {
                return Err(invalid(
                    field("radius_km"),
                    format!("must be > 0 km and finite, got {r}"),
                ));
            }
            (Some(_), None) => {
                return Err(invalid(
                    field("random_attitude"),
                    "only for a `projectile_pile`, got it with `radius_km`".into(),
                ));
            }
            (None, Some(rel)) => {
                let path = join_clean(base_dir, rel);
                let pile = ProjectilePile::read(&path, p.random_attitude.unwrap_or(true))
                    .map_err(|e| invalid(field("projectile_pile"), one_line(&e.to_string())))?;
                let spec = pile.equivalent_spec(p.id.clone(), speed * 1e3);
                piles.push((p.id.clone(), pile));
                spec
            }
            (r, _) => {
                return Err(invalid(
                    field(if r.is_some() { "projectile_pile" } else { "radius_km" }),
                    "give exactly one of `radius_km` (km, a single ellipsoid) and `projectile_pile` (a bodies \
                     file)"
                        .into(),
                ));
            }
        };
        custom.push((p.id.clone(), spec));
    }

    // [campaign] lists
    listed(c.targets.is_empty(), "targets", "target bodies file")?;
    let mut targets: Vec<(String, PathBuf, Vec<Body>)> = Vec::new();
    for (k, rel) in c.targets.iter().enumerate() {
        let field = format!("campaign.targets[{k}]");
        let path = join_clean(base_dir, rel);
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        if stem.is_empty() {
            return Err(invalid(
                field,
                format!("not a file name: {:?}", rel.display().to_string()),
            ));
        }
        if targets.iter().any(|(s, _, _)| *s == stem) {
            return Err(invalid(
                field,
                format!("another target file is also named `{stem}` (its stem names the run directories)"),
            ));
        }
        let bodies = read_target(&path).map_err(|e| invalid(field.clone(), one_line(&e.to_string())))?;
        targets.push((stem, path, bodies));
    }
    listed(c.projectiles.is_empty(), "projectiles", "projectile")?;
    let mut projectiles: Vec<ProjectileSpec> = Vec::new();
    for (k, id) in c.projectiles.iter().enumerate() {
        let field = format!("campaign.projectiles[{k}]");
        let p = match (ProjectileSpec::preset(id), custom.iter().find(|(c, _)| c == id)) {
            (Some(mut p), _) => {
                p.speed = speed_km_s * 1e3;
                p
            }
            (None, Some((_, p))) => p.clone(),
            (None, None) => {
                return Err(invalid(
                    field,
                    format!("expected P1, P2, P3 or the id of a [[projectile]] table, got {id:?}"),
                ));
            }
        };
        if projectiles.iter().any(|q| q.id == p.id) {
            return Err(invalid(field, format!("`{}` is listed twice", p.id)));
        }
        projectiles.push(p);
    }
    listed(c.angles.is_empty(), "angles", "angle (degrees)")?;
    let mut angles: Vec<f64> = Vec::new();
    for (k, &a) in c.angles.iter().enumerate() {
        let field = format!("campaign.angles[{k}]");
        if !(0.0..=180.0).contains(&a) {
            return Err(invalid(field, format!("expected 0 to 180 degrees, got {a}")));
        }
        let a = a + 0.0; // -0 → 0
        if angles.contains(&a) {
            return Err(invalid(field, format!("{a} is listed twice")));
        }
        angles.push(a);
    }
    listed(c.seeds.is_empty(), "seeds", "seed")?;
    let mut seen = HashSet::new();
    for (k, s) in c.seeds.iter().enumerate() {
        if !seen.insert(*s) {
            return Err(invalid(format!("campaign.seeds[{k}]"), format!("{s} is listed twice")));
        }
    }

    let snapshots = match (&imp.snapshots, imp.snapshot_every) {
        (Some(_), Some(every)) => {
            return Err(invalid(
                "impact.snapshot_every".into(),
                format!(
                    "give either `snapshots` (the list) or `snapshot_every` (their cadence), not both; got {every}"
                ),
            ));
        }
        (Some(times), None) => times.clone(),
        (None, Some(every)) => {
            use crate::io::output_times::{cadence_count, cadence_times};
            use crate::io::scene_file::{MAX_SNAPSHOTS, MIN_MEANINGFUL};
            if !(every.is_finite() && every >= MIN_MEANINGFUL) {
                return Err(invalid(
                    "impact.snapshot_every".into(),
                    format!("must be > 0 s and finite, got {every}"),
                ));
            }
            if !(t_end.is_finite() && t_end > 0.0) || cadence_count(t_end, every) > MAX_SNAPSHOTS as f64 {
                return Err(invalid(
                    "impact.snapshot_every".into(),
                    format!("too small for t_end = {t_end}: at most {MAX_SNAPSHOTS} snapshots, got {every}"),
                ));
            }
            cadence_times(t_end, every)
        }
        (None, None) => default_snapshots(t_end),
    };

    // The grid; each configuration validated (an error names the campaign's field).
    let mut points = Vec::new();
    for (stem, path, bodies) in &targets {
        for (pk, projectile) in projectiles.iter().enumerate() {
            let mut base = ImpactConfig::new(path.clone(), projectile.clone());
            base.t_end = t_end;
            base.method = imp.method.unwrap_or(crate::integrate::Method::BulirschStoer);
            base.rtol = imp.rtol.unwrap_or(default_rtol(base.method));
            base.f0 = imp.f0.unwrap_or(DEFAULT_F0);
            base.beta = imp.beta.unwrap_or(DEFAULT_BETA);
            base.kappa_reading = imp.kappa_reading.unwrap_or_default();
            base.contact_time = imp.contact_time.unwrap_or(DEFAULT_CONTACT_TIME);
            base.every = imp.every.unwrap_or(DEFAULT_EVERY);
            base.inertia = imp.inertia.unwrap_or_default();
            base.snapshots = snapshots.clone();
            base.geometry = imp.geometry().map_err(|e| match e {
                ImpactError::Invalid { field, message } => invalid(format!("impact.{field}"), message),
                other => invalid("impact".into(), other.to_string()),
            })?;
            base.pile = piles
                .iter()
                .find(|(id, _)| *id == projectile.id)
                .map(|(_, p)| p.clone());
            let projectile_field = || match custom.iter().position(|(id, _)| *id == projectile.id) {
                Some(j) => format!("projectile[{j}]"),
                None => format!("campaign.projectiles[{pk}]"),
            };
            base.validate().map_err(|e| match e {
                ImpactError::Invalid { field, message }
                    if field.starts_with("projectile") && !field.starts_with("projectile_") =>
                {
                    invalid(projectile_field(), format!("{field}: {message}"))
                }
                ImpactError::Invalid { field, message } => invalid(format!("impact.{field}"), message),
                other => invalid("impact".into(), other.to_string()),
            })?;
            base.kappa(bodies).map_err(|e| {
                let message = match e {
                    ImpactError::Invalid { message, .. } => message,
                    other => other.to_string(),
                };
                invalid(projectile_field(), format!("on target `{stem}`: {message}"))
            })?;
            for &angle in &angles {
                for &seed in &c.seeds {
                    let config = ImpactConfig {
                        angle_deg: angle,
                        seed,
                        ..base.clone()
                    };
                    let plan = config.plan(bodies).map_err(|e| match e {
                        ImpactError::Invalid { field, message } => {
                            invalid(format!("impact.{field}"), format!("on target `{stem}`: {message}"))
                        }
                        other => invalid("impact".into(), other.to_string()),
                    })?;
                    points.push(GridPoint {
                        name: format!("{stem}_{}_z{angle}_s{seed}", projectile.id),
                        target: stem.clone(),
                        projectile: projectile.id.clone(),
                        angle_deg: angle,
                        seed,
                        config,
                        plan,
                        overrides: Vec::new(),
                    });
                }
            }
        }
    }
    Ok(Campaign {
        name: name.to_string(),
        out: join_clean(base_dir, &c.out),
        parallel,
        points,
        file,
        source: None,
    })
}
