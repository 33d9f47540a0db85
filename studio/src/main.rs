//! `taut <command>`: the host tools (see the crate's documentation and
//! `taut --help`).

use clap::Parser;
use std::process::ExitCode;
use taut_studio::cli::Cli;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let name = cli.command.name();
    match cli.command.run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("taut {name}: {e}");
            ExitCode::FAILURE
        }
    }
}
