//! `rubblepile campaign slurm`: a Slurm job-array script running a campaign as shards
//! ([`rubblepile::impact::campaign::shard`]), written so that it runs only what it says.
//!
//! - Every value put into the script is quoted for the reader that reads it: shell words in single quotes
//!   ([`sh_quote`]; a path holding `;`, `$(…)`, a backtick or a quote stays one word and is never run), `#SBATCH`
//!   values escaped for sbatch's own reading of its directives ([`sbatch_quote`]: a backslash before every character
//!   but letters, digits and `_ . / - : , + = @ %`; a `%` of a path doubled, since Slurm reads `%A`, `%a` … in file
//!   names).
//! - A value holding a newline, a carriage return or a NUL is refused (it would end a line or a string early);
//!   the binary, the campaign file and the campaign directory are written by their absolute paths.
//! - The scheduler options are checked as Slurm reads them ([`SlurmJob::check`]): `--time` in one of Slurm's forms
//!   with minutes and seconds below 60 and hours below 24 where a larger unit precedes them, at most
//!   [`MAX_TIME_DAYS`] days; `--mem` a whole number with an optional unit `K`, `M`, `G` or `T`, at most
//!   [`MAX_MEM_MB`] MB; partition and account names of letters, digits and `_ . - ,`.

use std::path::{Path, PathBuf};

use rubblepile::impact::campaign::{Campaign, CampaignError, load_campaign};

/// Longest `--time` accepted: 365 days (no cluster grants more; a larger value is a typo).
pub const MAX_TIME_DAYS: u64 = 365;

/// Largest `--mem` accepted (MB): 64 TiB, beyond the memory of any single node.
pub const MAX_MEM_MB: u64 = 64 << 20;

/// Longest partition or account name accepted (characters).
pub const MAX_NAME_LEN: usize = 255;

/// What the Slurm script of `campaign slurm` asks of the scheduler and which binary it runs (options named as
/// `sbatch`'s).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SlurmJob {
    /// Array tasks (shards), at least 1.
    pub tasks: usize,
    /// Cores per task, at least 1.
    pub threads: usize,
    /// `--time` (wall-clock limit per task: `MINUTES`, `HH:MM:SS`, `D-HH:MM`, …); `None`: the partition's default.
    pub time: Option<String>,
    /// `--partition`; `None`: the cluster's default.
    pub partition: Option<String>,
    /// `--account` charged; `None`: the user's default.
    pub account: Option<String>,
    /// `--mem` per node (e.g. `4G`, `500M`; a bare number is MB); `None`: the partition's default.
    pub mem: Option<String>,
    /// Most array tasks running at once (`--array=0-(N-1)%K`); `None`: no limit.
    pub throttle: Option<usize>,
    /// The rubblepile executable the tasks run (made absolute by [`SlurmPaths::resolve`]).
    pub binary: PathBuf,
}

impl SlurmJob {
    /// Checks the options as `sbatch` would read them, naming the option at fault (`(option, why)`): counts at
    /// least 1, [`slurm_time_minutes`] for `--time`, [`slurm_mem_mb`] for `--mem`, and partition and account names
    /// of letters, digits and `_ . - ,` (nothing the shell or sbatch would read otherwise).
    pub fn check(&self) -> Result<(), (String, String)> {
        let bad = |opt: &str, why: &str, got: &str| Err((format!("--{opt}"), format!("{why}, got {got:?}")));
        if self.tasks == 0 {
            return bad("tasks", "must be at least 1", "0");
        }
        if self.threads == 0 {
            return bad("threads-per-task", "must be at least 1", "0");
        }
        if self.throttle == Some(0) {
            return bad("throttle", "must be at least 1 (array tasks at once)", "0");
        }
        if let Some(t) = &self.time
            && let Err(why) = slurm_time_minutes(t)
        {
            return bad("time", &why, t);
        }
        if let Some(m) = &self.mem
            && let Err(why) = slurm_mem_mb(m)
        {
            return bad("mem", &why, m);
        }
        for (opt, value) in [("partition", &self.partition), ("account", &self.account)] {
            if let Some(v) = value
                && (v.is_empty()
                    || v.len() > MAX_NAME_LEN
                    || !v.bytes().all(|b| b.is_ascii_alphanumeric() || b"_.-,".contains(&b)))
            {
                return bad(
                    opt,
                    &format!("must be a name of 1 to {MAX_NAME_LEN} letters, digits, '_', '.', '-' or ','"),
                    v,
                );
            }
        }
        Ok(())
    }
}

/// The limit `t` (`sbatch --time`) in minutes (seconds rounded up), or why it is not one of Slurm's forms:
/// `MINUTES`, `MINUTES:SECONDS`, `HOURS:MINUTES:SECONDS`, `DAYS-HOURS`, `DAYS-HOURS:MINUTES`,
/// `DAYS-HOURS:MINUTES:SECONDS`; seconds below 60, minutes below 60 after hours, hours below 24 after days; at
/// most [`MAX_TIME_DAYS`] days. `0` (no limit, in Slurm) is accepted.
pub fn slurm_time_minutes(t: &str) -> Result<u64, String> {
    const FORMS: &str = "must be a Slurm time limit: MINUTES, MINUTES:SECONDS, HOURS:MINUTES:SECONDS, DAYS-HOURS, \
                         DAYS-HOURS:MINUTES or DAYS-HOURS:MINUTES:SECONDS";
    let number = |s: &str| -> Result<u64, String> {
        if s.is_empty() || s.len() > 9 || !s.bytes().all(|b| b.is_ascii_digit()) {
            return Err(FORMS.to_string());
        }
        s.parse::<u64>().map_err(|_| FORMS.to_string())
    };
    let below = |v: u64, limit: u64, what: &str| {
        if v < limit {
            Ok(v)
        } else {
            Err(format!("{FORMS} ({what} must be below {limit})"))
        }
    };
    let seconds = match t.split_once('-') {
        Some((days, rest)) => {
            let days = number(days)?;
            let parts: Vec<&str> = rest.split(':').collect();
            let hours = below(number(parts[0])?, 24, "hours after days")?;
            let (minutes, secs) = match parts.len() {
                1 => (0, 0),
                2 => (below(number(parts[1])?, 60, "minutes")?, 0),
                3 => (
                    below(number(parts[1])?, 60, "minutes")?,
                    below(number(parts[2])?, 60, "seconds")?,
                ),
                _ => return Err(FORMS.to_string()),
            };
            ((days * 24 + hours) * 60 + minutes) * 60 + secs
        }
        None => {
            let parts: Vec<&str> = t.split(':').collect();
            match parts.len() {
                1 => number(parts[0])? * 60,
                2 => number(parts[0])? * 60 + below(number(parts[1])?, 60, "seconds")?,
                3 => {
                    let hours = number(parts[0])?;
                    let minutes = below(number(parts[1])?, 60, "minutes")?;
                    let secs = below(number(parts[2])?, 60, "seconds")?;
                    (hours * 60 + minutes) * 60 + secs
                }
                _ => return Err(FORMS.to_string()),
            }
        }
    };
    if seconds > MAX_TIME_DAYS * 86_400 {
        return Err(format!("{FORMS}, at most {MAX_TIME_DAYS} days"));
    }
    Ok(seconds.div_ceil(60))
}

/// The memory `m` (`sbatch --mem`) in MB, or why it is not a whole number with an optional unit `K`, `M`, `G` or
/// `T` (a bare number is MB) of at most [`MAX_MEM_MB`] MB. `0` (all of a node's memory, in Slurm) is accepted.
pub fn slurm_mem_mb(m: &str) -> Result<u64, String> {
    let form =
        || "must be a whole number with an optional unit K, M, G or T (e.g. 4G; a bare number is MB)".to_string();
    let (digits, unit) = match m.as_bytes().last() {
        Some(b'K' | b'M' | b'G' | b'T') => (&m[..m.len() - 1], &m[m.len() - 1..]),
        _ => (m, "M"),
    };
    if digits.is_empty() || digits.len() > 12 || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return Err(form());
    }
    let n: u64 = digits.parse().map_err(|_| form())?;
    let mb = match unit {
        "K" => n.div_ceil(1024),
        "M" => n,
        "G" => n.saturating_mul(1024),
        _ => n.saturating_mul(1024 * 1024),
    };
    if mb > MAX_MEM_MB {
        return Err(format!(
            "must be at most {}T ({MAX_MEM_MB} MB), more than any node has",
            MAX_MEM_MB >> 20
        ));
    }
    Ok(mb)
}

/// `s` as one shell word: as it is when it holds only letters, digits and `_ . / - : , + = @ %`, else in single
/// quotes (a single quote inside written `'\''`). Nothing in it is expanded or run by the shell.
pub fn sh_quote(s: &str) -> String {
    let plain = |b: u8| b.is_ascii_alphanumeric() || b"_./-:,+=@%".contains(&b);
    if !s.is_empty() && s.bytes().all(plain) {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}

/// `s` as one argument of an `#SBATCH` line, which sbatch reads itself (not the shell): a backslash before every
/// character but letters, digits and `_ . / - : , + = @ %` (sbatch drops a backslash and keeps the character after
/// it, so quotes, spaces and `#` lose their meaning). A `%` is left to the caller (Slurm expands `%A`, `%a` … in
/// file names: double it to keep it).
pub fn sbatch_quote(s: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "_./-:,+=@%".contains(c);
    let mut out = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        if !plain(c) {
            out.push('\\');
        }
        out.push(c);
    }
    out
}

/// The absolute paths a job script names, each checked to hold no newline, carriage return or NUL.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SlurmPaths {
    /// The rubblepile executable.
    pub binary: PathBuf,
    /// The campaign file.
    pub file: PathBuf,
    /// The campaign directory.
    pub out: PathBuf,
}

impl SlurmPaths {
    /// Makes `binary`, `file` and `out` absolute (against the current directory) and checks them; the error names
    /// the option (`--binary`, `FILE`, `--out`) and says why.
    pub fn resolve(binary: &Path, file: &Path, out: &Path) -> Result<SlurmPaths, (String, String)> {
        let one = |opt: &str, p: &Path| -> Result<PathBuf, (String, String)> {
            let text = p.to_str().ok_or_else(|| {
                (
                    opt.to_string(),
                    format!("{} is not valid UTF-8; a job script names it as text", p.display()),
                )
            })?;
            if let Some(c) = text.chars().find(|c| matches!(c, '\n' | '\r' | '\0')) {
                return Err((
                    opt.to_string(),
                    format!(
                        "must not hold a {} (it would end a line of the job script early), got {text:?}",
                        match c {
                            '\n' => "newline",
                            '\r' => "carriage return",
                            _ => "NUL",
                        }
                    ),
                ));
            }
            std::path::absolute(p).map_err(|e| (opt.to_string(), format!("{}: {e}", p.display())))
        };
        Ok(SlurmPaths {
            binary: one("--binary", binary)?,
            file: one("FILE", file)?,
            out: one("--out", out)?,
        })
    }
}

/// `s` as a path (checked UTF-8 by [`SlurmPaths::resolve`]).
fn text(p: &Path) -> String {
    p.to_string_lossy().into_owned()
}

/// A Slurm job-array script running the campaign of `runs` grid points from `paths.file` into `paths.out` as
/// `job.tasks` shards, one array task each, with `job.threads` cores per task and the scheduler options of `job`;
/// its tasks call `paths.binary`. Every value is quoted (module docs).
pub fn slurm_script(runs: usize, paths: &SlurmPaths, job: &SlurmJob) -> String {
    let (bin, file, out) = (text(&paths.binary), text(&paths.file), text(&paths.out));
    // The job's name: the campaign file's stem, made of what every scheduler's tools show plainly.
    let name: String = paths
        .file
        .file_stem()
        .map_or("campaign".into(), |s| s.to_string_lossy().into_owned())
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "_.-".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    let tasks = job.tasks;
    let mut options = String::new();
    for (opt, value) in [
        ("time", &job.time),
        ("partition", &job.partition),
        ("account", &job.account),
        ("mem", &job.mem),
    ] {
        if let Some(v) = value {
            options.push_str(&format!("#SBATCH --{opt}={}\n", sbatch_quote(v)));
        }
    }
    let script = format!("{out}/campaign.slurm");
    let merge = format!("{} campaign merge {}", sh_quote(&bin), sh_quote(&out));
    // Slurm expands `%…` in file names: a `%` of the directory is doubled to stay itself.
    let output = sbatch_quote(&format!("{}/slurm-%A_%a.out", out.replace('%', "%%")));
    format!(
        "#!/bin/bash\n\
         # {runs} impact runs of {file_q} in {tasks} shards (written by `rubblepile campaign slurm`).\n\
         # Submit:  jobid=$(sbatch --parsable {script_q})\n\
         # Then:    sbatch --dependency=afterany:$jobid --wrap {merge_q}\n\
         # A task that dies leaves its finished runs and checkpoints; resubmitting the array resumes them.\n\
         #SBATCH --job-name=rubblepile-{name}\n\
         #SBATCH --array=0-{last}{throttle}\n\
         #SBATCH --ntasks=1\n\
         #SBATCH --cpus-per-task={threads}\n\
         {options}\
         #SBATCH --output={output}\n\
         set -euo pipefail\n\
         export RAYON_NUM_THREADS=$SLURM_CPUS_PER_TASK\n\
         srun {bin_q} campaign {file_q} --out {out_q} --shard $SLURM_ARRAY_TASK_ID/{tasks} --parallel 1 \
         --no-progress\n",
        file_q = sh_quote(&file),
        script_q = sh_quote(&script),
        merge_q = sh_quote(&merge),
        bin_q = sh_quote(&bin),
        out_q = sh_quote(&out),
        last = tasks - 1,
        threads = job.threads,
        throttle = job.throttle.map_or(String::new(), |k| format!("%{k}")),
    )
}

/// Where `campaign slurm` writes its script.
pub fn slurm_script_path(campaign: &Campaign) -> PathBuf {
    campaign.out.join("campaign.slurm")
}

/// Writes the Slurm job array of the campaign file `file` (its directory `out` when given, else `campaign.out`) as
/// `DIR/campaign.slurm` (not submitted): returns the script's path, the number of runs and the campaign directory.
pub fn write_slurm(
    file: &Path,
    out: Option<&Path>,
    job: &SlurmJob,
) -> Result<(PathBuf, usize, PathBuf), CampaignError> {
    let invalid = |(field, message)| rubblepile::io::scene_file::SceneError::Invalid {
        file: file.display().to_string(),
        field,
        message,
    };
    job.check().map_err(invalid)?;
    let mut campaign = load_campaign(file)?;
    if let Some(o) = out {
        campaign.out = o.to_path_buf();
    }
    let abs_file = campaign.source.clone().unwrap_or_else(|| file.to_path_buf());
    let paths = SlurmPaths::resolve(&job.binary, &abs_file, &campaign.out).map_err(invalid)?;
    campaign.out = paths.out.clone();
    let text = slurm_script(campaign.points.len(), &paths, job);
    let path = slurm_script_path(&campaign);
    let io = |source| CampaignError::Io {
        path: path.clone(),
        source,
    };
    std::fs::create_dir_all(&campaign.out).map_err(io)?;
    rubblepile::io::safe_write::write_atomic(&path, text).map_err(io)?;
    Ok((path, campaign.points.len(), campaign.out))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slurm_times_are_read_in_every_form_and_out_of_range_fields_refused() {
        for (t, minutes) in [
            ("90", 90),
            ("0", 0),
            ("10:30", 11),
            ("1:30:00", 90),
            ("1-0", 1440),
            ("1-02:30", 1590),
            ("1-02:30:00", 1590),
            ("365-0", 525_600),
        ] {
            assert_eq!(slurm_time_minutes(t), Ok(minutes), "{t}");
        }
        for t in [
            "1:99:99",
            "1-25:00",
            "1-",
            "-1",
            "2 hours",
            "1:2:3:4",
            "10:60",
            "366-0",
            "",
            "99999999999999999999",
            "1-1:1:1:1",
            "+5",
        ] {
            assert!(slurm_time_minutes(t).is_err(), "{t} accepted");
        }
    }

    #[test]
    fn memory_has_a_unit_and_a_ceiling() {
        assert_eq!(slurm_mem_mb("500"), Ok(500));
        assert_eq!(slurm_mem_mb("16G"), Ok(16 * 1024));
        assert_eq!(slurm_mem_mb("2048K"), Ok(2));
        assert_eq!(slurm_mem_mb("64T"), Ok(MAX_MEM_MB));
        for m in ["99999999999999999999G", "65T", "16GB", "G", "", "-1", "1.5G", "4 G"] {
            assert!(slurm_mem_mb(m).is_err(), "{m} accepted");
        }
    }

    #[test]
    fn quoting_keeps_plain_words_and_wraps_the_rest() {
        assert_eq!(sh_quote("/opt/rp/bin/rubblepile"), "/opt/rp/bin/rubblepile");
        assert_eq!(sh_quote("a b"), "'a b'");
        assert_eq!(sh_quote("it's"), "'it'\\''s'");
        assert_eq!(sh_quote(""), "''");
        assert_eq!(sbatch_quote("/a b/#x\"y'z%"), "/a\\ b/\\#x\\\"y\\'z%");
    }
}
