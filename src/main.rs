//! `rubblepile`: the command line ([`cli`]) and the programs it runs on top of the library: the benchmarks and
//! timed systems ([`bench`]), campaigns launched on clusters ([`cluster`]) and the three papers' reports
//! ([`studies`]).

mod bench;
mod choice;
mod cli;
mod cluster;
mod studies;
#[cfg(test)]
mod test_dirs;

fn main() -> std::process::ExitCode {
    cli::main()
}
