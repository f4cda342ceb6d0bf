//! The tables of `analysis/roig2003/REFEREE.md` (Roig et al. 2003 after the referee, issue 42):
//! [`rubblepile::analysis::roig2003_referee`]. Run by `analysis/roig2003/referee_tables.sh`.
//!
//! ```sh
//! cargo run --release --example roig2003_referee -- collect runs/referee analysis/roig2003   # runs -> CSVs
//! cargo run --release --example roig2003_referee -- report analysis/roig2003                 # CSVs -> REFEREE.md
//! ```

use std::path::Path;
use std::process::ExitCode;

use rubblepile::analysis::roig2003_referee::{collect, write_csvs, write_report};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.iter().map(String::as_str).collect::<Vec<_>>().as_slice() {
        ["collect", runs, out] => collect(Path::new(runs)).and_then(|(r, e)| {
            write_csvs(Path::new(out), &r, &e)?;
            println!("collected {} runs and {} equilibrium rows into {out}", r.len(), e.len());
            Ok(())
        }),
        ["report", out] => write_report(Path::new(out)).map(|p| println!("wrote {}", p.display())),
        _ => {
            eprintln!("usage: roig2003_referee collect RUNS_DIR OUT_DIR | report OUT_DIR");
            return ExitCode::from(2);
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
