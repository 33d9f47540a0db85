//! `cargo xtask studio [--port N] [--machine NAME] [--vcd FILE]`: the web
//! app (`taut studio`) against the simulated Mega: the release image in
//! simavr behind a pseudo-terminal, powered on as NAME (default flatbed),
//! connected at start; the trace goes to FILE (default
//! `target/studio/studio.vcd`) when the app ends on Ctrl-C.

use crate::firmware;
use crate::run::{self, root, Result};

pub const USAGE: &str =
    "cargo xtask studio [--port 8080] [--machine flatbed] [--vcd target/studio/studio.vcd]";

pub fn run(args: &[String]) -> Result<()> {
    let (mut port, mut machine) = ("8080".to_string(), "flatbed".to_string());
    let mut vcd = root().join("target/studio/studio.vcd");
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = || {
            it.next()
                .cloned()
                .ok_or(format!("{a} needs a value\n{USAGE}"))
        };
        match a.as_str() {
            "--port" => port = value()?,
            "--machine" => machine = value()?,
            "--vcd" => vcd = value()?.into(),
            _ => return Err(format!("unknown option {a}\n{USAGE}").into()),
        }
    }
    if let Some(dir) = vcd.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let img = firmware::build_release()?;
    println!(
        "== taut studio on the simulated {machine} (trace: {} when it ends)",
        vcd.display()
    );
    // The simulator is built into taut only with the `sim` feature.
    let mut c = run::cargo_cmd(
        &[
            "run",
            "--quiet",
            "--release",
            "-p",
            "taut-studio",
            "--features",
            "sim",
            "--bin",
            "taut",
            "--",
        ],
        &root(),
    );
    c.args([
        "studio".to_string(),
        "--port".into(),
        port,
        "--sim".into(),
        img.elf.display().to_string(),
        "--machine".into(),
        machine,
        "--vcd".into(),
        vcd.display().to_string(),
    ]);
    run::status(&mut c)
}
