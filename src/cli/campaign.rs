//! `rubblepile campaign FILE.toml`: a grid of impact runs (see [`crate::impact::campaign`] for the file
//! format, the campaign directory and how interrupted campaigns resume).

use std::path::PathBuf;

use crate::cli::{CheckpointArgs, CliError};
use crate::impact::campaign::{CampaignOptions, load_campaign, run_campaign};

/// `rubblepile campaign`.
#[derive(Debug, clap::Args)]
pub struct CampaignArgs {
    /// Campaign file (TOML): `[campaign]` out, targets, projectiles, angles, seeds, parallel; optional
    /// `[impact]` overrides and `[[projectile]]` custom projectiles.
    pub file: PathBuf,
    /// Runs at once (overrides `campaign.parallel`).
    #[arg(long, value_name = "N")]
    pub parallel: Option<usize>,
    /// Never show the progress display (it is shown only when stderr is a terminal anyway).
    #[arg(long)]
    pub no_progress: bool,
    /// Checkpoint options of every run.
    #[command(flatten)]
    pub checkpoints: CheckpointArgs,
}

/// Runs `campaign`: one line per finished run and a one-line summary on stdout. Exit code 2 for a bad
/// campaign file, 1 when a run failed (the others still ran), 3 when runs stopped after a checkpoint on
/// request (`--stop-after-checkpoints`).
pub fn campaign(args: &CampaignArgs) -> Result<(), CliError> {
    if args.parallel == Some(0) {
        return Err(CliError::usage("--parallel: must be at least 1, got 0"));
    }
    let options = CampaignOptions {
        run: args.checkpoints.options(!args.no_progress)?,
        parallel: args.parallel,
        verbose: true,
    };
    let campaign = load_campaign(&args.file).map_err(|e| CliError {
        message: e.to_string(),
        code: e.exit_code(),
    })?;
    let report = run_campaign(&campaign, &options).map_err(|e| CliError {
        message: e.to_string(),
        code: e.exit_code(),
    })?;
    println!("{}", report.one_line());
    let csv = campaign.out.join(crate::impact::campaign::CAMPAIGN_CSV);
    if report.failed() > 0 {
        return Err(CliError::failed(format!(
            "{} of {} runs failed (causes in {})",
            report.failed(),
            report.runs.len(),
            csv.display()
        )));
    }
    let stopped = report.runs.iter().filter(|r| r.stopped).count();
    if stopped > 0 {
        return Err(CliError {
            message: format!(
                "{stopped} runs stopped after a checkpoint (--stop-after-checkpoints); run the campaign again to resume them"
            ),
            code: 3,
        });
    }
    Ok(())
}
