//! The `mandelreel` binary: parses arguments, runs the command, and turns an
//! error chain into a message and an exit code (see `cli::EXIT_*`).

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = mandelreel::cli::Cli::parse();
    match mandelreel::cli::run(cli) {
        Ok(()) => ExitCode::from(mandelreel::cli::EXIT_OK),
        Err(error) => {
            // `status` has already said what is incomplete; no "error:" for that.
            if !error.is::<mandelreel::cli::Incomplete>() {
                eprintln!("error: {error:#}");
            }
            ExitCode::from(mandelreel::cli::exit_code(&error))
        }
    }
}
