//! Units on the command line: every flag that carries a dimensional quantity names its unit as a suffix (`-s`, `-h`,
//! `-m`, `-km`, `-m-s`, `-km-s`, `-deg`, `-kg`, `-kg-m3`, `-rad-s`); old spellings still parse, with a warning.

/// Renamed flags: (subcommand words it applies to, "" for every command; old name; new name; unit). A rename, not a
/// rescale: the value keeps the old flag's unit.
pub const RENAMED: &[(&str, &str, &str, &str)] = &[
    ("", "checkpoint-every", "checkpoint-every-s", "s"),
    ("", "checkpoint-every-sim", "checkpoint-every-sim-s", "s"),
    ("", "progress-every", "progress-every-s", "s"),
    ("", "max-wall-seconds", "max-wall-s", "s"),
    ("target build", "period-hours", "period-h", "h"),
    ("target build", "total-mass", "total-mass-kg", "kg"),
    ("impact", "projectile-radius", "projectile-radius-km", "km"),
    ("impact", "projectile-speed", "projectile-speed-km-s", "km/s"),
    ("impact", "angle", "angle-deg", "degrees"),
    ("impact", "contact-time", "contact-time-s", "s"),
    ("impact", "t-end", "t-end-s", "s"),
    ("impact", "snapshots", "snapshots-s", "s"),
    ("impact", "snapshot-every", "snapshot-every-s", "s"),
    ("impact", "every", "every-s", "s"),
    ("flyby", "period-hours", "period-h", "h"),
    ("flyby", "planet-mass", "planet-mass-kg", "kg"),
    ("flyby", "settle-max-hours", "settle-max-h", "h"),
    ("analyze", "at", "at-s", "s"),
    ("analyze-campaign", "at", "at-s", "s"),
    ("analyze-campaign", "spin-angle", "spin-angle-deg", "degrees"),
    ("report roig2003", "at", "at-s", "s"),
    ("report-roig2003", "at", "at-s", "s"),
    ("bench work-precision", "max-run-seconds", "max-run-s", "s"),
    ("bench impact", "angle", "angle-deg", "degrees"),
    ("bench impact", "t-end", "t-end-s", "s"),
    ("bench impact", "goal", "goal-s", "s"),
    ("bench scaling", "window", "window-s", "s"),
    ("bench scaling", "n200-t-end", "n200-t-end-s", "s"),
    ("bench scaling", "campaign-t-end", "campaign-t-end-s", "s"),
    ("bench hsdem", "from", "from-s", "s"),
    ("bench hsdem", "t-end", "t-end-s", "s"),
    ("bench critical", "from", "from-h", "h"),
    ("bench critical", "to", "to-h", "h"),
    ("bench critical", "step", "step-h", "h"),
    ("bench critical", "hold", "hold-s", "s"),
    ("ssdem advise", "radius", "radius-m", "m"),
    ("ssdem advise", "density", "density-kg-m3", "kg/m³"),
    ("ssdem advise", "body-radius", "body-radius-m", "m"),
    ("ssdem advise", "bulk-density", "bulk-density-kg-m3", "kg/m³"),
    ("ssdem advise", "speed", "speed-m-s", "m/s"),
    ("aggregate build", "radius", "radius-m", "m"),
    ("aggregate build", "radius-range", "radius-range-m", "m"),
    ("aggregate build", "bulk-density", "bulk-density-kg-m3", "kg/m³"),
    ("aggregate build", "core-radius", "core-radius-m", "m"),
    ("aggregate density", "bulk-density", "bulk-density-kg-m3", "kg/m³"),
    ("spinup critical", "from", "from-h", "h"),
    ("spinup critical", "to", "to-h", "h"),
    ("spinup critical", "step", "step-h", "h"),
    ("spinup critical", "hold", "hold-s", "s"),
    ("spinup critical", "judge-window", "judge-window-s", "s"),
    ("spinup density-fit", "period", "period-h", "h"),
    ("spinup judge", "judge-window", "judge-window-s", "s"),
    ("render", "perspective", "perspective-deg", "degrees"),
    ("render", "extent", "extent-m", "m"),
];

/// `args` with every renamed flag of its subcommand in its new spelling (`--old V` and `--old=V`; nothing after a bare
/// `--`), a negative value joined to its flag (`--x -5` → `--x=-5`), and one warning line per old flag used.
pub fn rewrite(args: Vec<String>) -> (Vec<String>, Vec<String>) {
    let words: Vec<String> = args
        .iter()
        .skip(1)
        .take_while(|a| !a.starts_with('-'))
        .cloned()
        .collect();
    let applies = |scope: &str| {
        scope
            .split_whitespace()
            .enumerate()
            .all(|(i, w)| words.get(i).is_some_and(|x| x == w))
    };
    let mut warnings: Vec<String> = Vec::new();
    let mut out = Vec::with_capacity(args.len());
    let mut rest = false;
    for a in args {
        rest |= a == "--";
        let (name, value) = a.split_once('=').map_or((a.as_str(), None), |(n, v)| (n, Some(v)));
        let hit = RENAMED
            .iter()
            .find(|r| !rest && name.strip_prefix("--") == Some(r.1) && applies(r.0));
        match hit {
            Some((_, old, new, unit)) => {
                let w = format!("warning: --{old} is deprecated: use --{new} (same unit, {unit})");
                if !warnings.contains(&w) {
                    warnings.push(w);
                }
                out.push(value.map_or_else(|| format!("--{new}"), |v| format!("--{new}={v}")));
            }
            None if !rest && is_negative_value(&a) && out.last().is_some_and(|f: &String| takes_value_next(f)) => {
                // clap reads `--x -5` as two flags; `--x=-5` reaches the flag's own check.
                let flag = out.pop().unwrap_or_default();
                out.push(format!("{flag}={a}"));
            }
            None => out.push(a),
        }
    }
    (out, warnings)
}

/// A negative number or list (`-5`, `-1e-3`, `-.5`, `-1,0,0`): never a flag of ours.
fn is_negative_value(a: &str) -> bool {
    a.strip_prefix('-')
        .and_then(|r| r.chars().find(|c| *c != '.'))
        .is_some_and(|c| c.is_ascii_digit())
}

/// A long flag written without `=` (`--x`), which may take the next word as its value.
fn takes_value_next(a: &str) -> bool {
    a.len() > 2 && a.starts_with("--") && !a.contains('=')
}
