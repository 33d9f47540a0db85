//! The `taut` command line (clap, derived): one subcommand a module, each
//! with its `--help` (defaults and examples), refusal of unknown or
//! misspelt flags with a suggestion, missing arguments named, and
//! `taut completions SHELL` for the shells' completion scripts.

use crate::{app, bench, preview, send, stringart, template, text, vectorize};
use clap::{CommandFactory, Parser, Subcommand};

#[derive(Parser, Debug)]
#[command(
    name = "taut",
    version,
    about = "taut's host tools: pictures, SVG and text to plotter G-code, string-art cards, \
             templates, previews, a Grbl sender and the studio web app",
    after_help = "Run `taut <COMMAND> --help` for a command's options, defaults and examples.\n\
                  From the repository: cargo taut <COMMAND> … (cargo run --release --bin taut -- …)",
    arg_required_else_help = true
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    Stringart(stringart::Cli),
    Template(template::Cli),
    Vectorize(vectorize::Cli),
    Text(text::Cli),
    Preview(preview::Cli),
    Send(send::Cli),
    Studio(app::Cli),
    Bench(bench::Cli),
    /// Prints the completion script of a shell (bash, zsh, fish, elvish, powershell)
    #[command(
        after_help = "Example:\n  taut completions bash > ~/.local/share/bash-completion/completions/taut"
    )]
    Completions {
        /// The shell
        shell: clap_complete::Shell,
    },
}

impl Command {
    /// The subcommand's name, for error messages.
    pub fn name(&self) -> &'static str {
        match self {
            Command::Stringart(_) => "stringart",
            Command::Template(_) => "template",
            Command::Vectorize(_) => "vectorize",
            Command::Text(_) => "text",
            Command::Preview(_) => "preview",
            Command::Send(_) => "send",
            Command::Studio(_) => "studio",
            Command::Bench(_) => "bench",
            Command::Completions { .. } => "completions",
        }
    }

    pub fn run(self) -> Result<(), String> {
        match self {
            Command::Stringart(c) => stringart::run(c),
            Command::Template(c) => template::run(c),
            Command::Vectorize(c) => vectorize::run(c),
            Command::Text(c) => text::run(c),
            Command::Preview(c) => preview::run(c),
            Command::Send(c) => send::run(c),
            Command::Studio(c) => app::run(c),
            Command::Bench(c) => bench::run(c),
            Command::Completions { shell } => {
                clap_complete::generate(shell, &mut Cli::command(), "taut", &mut std::io::stdout());
                Ok(())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::args::{pair, positive};

    fn parse(words: &[&str]) -> Result<Cli, clap::Error> {
        Cli::try_parse_from(std::iter::once("taut").chain(words.iter().copied()))
    }

    #[test]
    fn the_command_line_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn misspelt_flags_get_a_suggestion_and_missing_ones_are_named() {
        let e = parse(&[
            "template", "--nails", "250", "--shape", "circle", "--radius", "40", "-o", "t.svg",
        ])
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("unexpected argument '--radius'") && e.contains("--radius-cm"),
            "{e}"
        );
        let e = parse(&[
            "vectorize",
            "horse.png",
            "--machine",
            "flatbed",
            "-o",
            "x.gcode",
            "--widht-mm",
            "5",
        ])
        .unwrap_err()
        .to_string();
        assert!(e.contains("--width-mm"), "{e}");
        let e = parse(&[
            "stringart",
            "horse.png",
            "--nails",
            "250",
            "--shape",
            "circle",
            "--lines",
            "10",
            "-o",
            "c",
        ])
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("required arguments were not provided") && e.contains("--radius-cm"),
            "{e}"
        );
        assert_eq!(pair("1, -2.5"), Ok([1.0, -2.5]));
        assert!(pair("1").is_err() && positive("0").is_err() && positive("x").is_err());
    }
}
