//! `rubblepile`: see [`rubblepile::cli`].

fn main() -> std::process::ExitCode {
    rubblepile::cli::main()
}
