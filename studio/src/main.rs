//! `taut <command>`: the host tools (see the crate's documentation).

use std::process::ExitCode;
use taut_studio::args::Args;
use taut_studio::{stringart, template};

const HELP: &str = "usage: taut <command> [args]  (cargo run --release --bin taut -- <command>)";

fn main() -> ExitCode {
    let raw: Vec<String> = std::env::args().skip(1).collect();
    let Some((command, rest)) = raw.split_first() else {
        eprintln!("{HELP}\n\n{}", stringart::USAGE);
        return ExitCode::FAILURE;
    };
    let result = match command.as_str() {
        "stringart" => Args::parse(rest, &[]).and_then(stringart::run),
        "template" => Args::parse(rest, &[]).and_then(template::run),
        "help" | "--help" | "-h" => {
            println!("{HELP}\n\n{}", stringart::USAGE);
            Ok(())
        }
        other => Err(format!("unknown command {other:?}\n{HELP}")),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("taut {command}: {e}");
            ExitCode::FAILURE
        }
    }
}
