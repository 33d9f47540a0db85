//! `taut <command>`: the host tools (see the crate's documentation).

use std::process::ExitCode;
use taut_studio::args::Args;
use taut_studio::{app, bench, preview, send, stringart, template, text, vectorize};

const HELP: &str = "usage: taut <command> [args]   (cargo run --release --bin taut -- <command> …)";

fn usage() -> String {
    [
        stringart::USAGE,
        template::USAGE,
        vectorize::USAGE,
        text::USAGE,
        preview::USAGE,
        send::USAGE,
        app::USAGE,
        bench::USAGE,
    ]
    .join("\n\n")
}

fn main() -> ExitCode {
    let raw: Vec<String> = std::env::args().skip(1).collect();
    let Some((command, rest)) = raw.split_first() else {
        eprintln!("{HELP}\n\n{}", usage());
        return ExitCode::FAILURE;
    };
    let run = |f: fn(Args) -> Result<(), String>| Args::parse(rest, &[]).and_then(f);
    let result = match command.as_str() {
        "stringart" => run(stringart::run),
        "template" => run(template::run),
        "vectorize" => run(vectorize::run),
        "text" => run(text::run),
        "preview" => run(preview::run),
        "send" => run(send::run),
        "studio" => run(app::run),
        "bench" => run(bench::run),
        "help" | "--help" | "-h" => {
            println!("{HELP}\n\n{}", usage());
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
