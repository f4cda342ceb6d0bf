//! `rubblepile report richardson2011`: the options, and the call into [`crate::studies::richardson2011::report`].

use std::path::PathBuf;

use super::common::CliError;
use crate::studies::richardson2011::report::{Richardson2011Inputs, write_report};

/// `rubblepile report richardson2011`.
#[derive(Debug, clap::Args)]
pub struct ReportRichardson2011Args {
    /// Model-atmosphere run directory in the radius-1.0 cylinder.
    #[arg(long, value_name = "DIR")]
    pub atmosphere: PathBuf,
    /// The same in the half-radius cylinder (optional).
    #[arg(long, value_name = "DIR")]
    pub half: Option<PathBuf>,
    /// Tumbler run directories, one per Froude number (optional, repeatable).
    #[arg(long, value_name = "DIR", num_args = 1..)]
    pub tumbler: Vec<PathBuf>,
    /// Where REPORT.md and figures/ go (NOTES.md there is appended to the report).
    #[arg(long, value_name = "DIR", default_value = "analysis/richardson2011")]
    pub out: PathBuf,
}

/// Runs the command.
pub fn report(args: &ReportRichardson2011Args) -> Result<(), CliError> {
    let inputs = Richardson2011Inputs {
        atmosphere: args.atmosphere.clone(),
        half: args.half.clone(),
        tumbler: args.tumbler.clone(),
        out: args.out.clone(),
    };
    let (path, figures) = write_report(&inputs).map_err(|e| {
        if e.is_input() {
            CliError::usage(e)
        } else {
            CliError::failed(e)
        }
    })?;
    println!(
        "wrote {} and {figures} figure files in {}",
        path.display(),
        inputs.out.join("figures").display()
    );
    Ok(())
}
