//! Running commands: cargo, the bootstrap script, the simulator CLI.

use std::path::{Path, PathBuf};
use std::process::Command;

pub type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

/// The repository root (xtask lives in `<root>/xtask`).
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

pub fn status(cmd: &mut Command) -> Result<()> {
    let st = cmd
        .status()
        .map_err(|e| format!("cannot run {cmd:?}: {e}"))?;
    if st.success() {
        Ok(())
    } else {
        Err(format!("{cmd:?} failed ({st})").into())
    }
}

/// A cargo command in `dir`. The toolchain comes from `dir`'s
/// rust-toolchain.toml, not from the xtask's own environment.
pub fn cargo_cmd(args: &[&str], dir: &Path) -> Command {
    let mut c = Command::new("cargo");
    c.args(args)
        .current_dir(dir)
        .env_remove("RUSTUP_TOOLCHAIN")
        .env_remove("CARGO_TARGET_DIR");
    c
}

pub fn cargo(args: &[&str], dir: &Path) -> Result<()> {
    status(&mut cargo_cmd(args, dir))
}

pub fn setup() -> Result<()> {
    status(Command::new("bash").arg(root().join("scripts/setup.sh")))
}

/// `taut-sim ELF ARGS…`, built optimised (it runs millions of instructions).
pub fn taut_sim(elf: &Path, args: &[String]) -> Result<()> {
    let mut all = vec![elf.display().to_string()];
    all.extend_from_slice(args);
    bin("taut-sim", &all)
}

/// `taut ARGS…`, the host tools (studio/), built optimised.
pub fn studio(args: &[String]) -> Result<()> {
    let mut c = cargo_cmd(
        &[
            "run",
            "--quiet",
            "--release",
            "-p",
            "taut-studio",
            "--bin",
            "taut",
            "--",
        ],
        &root(),
    );
    c.args(args);
    status(&mut c)
}

/// One of the harness crate's binaries (simavr/src/bin), built optimised.
pub fn bin(name: &str, args: &[String]) -> Result<()> {
    let mut c = cargo_cmd(
        &[
            "run",
            "--quiet",
            "--release",
            "-p",
            "taut-simavr",
            "--bin",
            name,
            "--",
        ],
        &root(),
    );
    c.args(args);
    status(&mut c)
}

/// A script running beside the build, its output kept in a log file.
pub struct Background {
    child: std::process::Child,
    what: String,
    log: std::path::PathBuf,
}

impl Background {
    pub fn start(what: &str, script: &Path, log: &Path) -> Result<Background> {
        if let Some(dir) = log.parent() {
            std::fs::create_dir_all(dir)?;
        }
        let out = std::fs::File::create(log)?;
        let child = Command::new(script)
            .stdout(out.try_clone()?)
            .stderr(out)
            .spawn()
            .map_err(|e| format!("{}: {e}", script.display()))?;
        println!("== {what}, in the background (log: {})", log.display());
        Ok(Background {
            child,
            what: what.to_string(),
            log: log.to_owned(),
        })
    }

    /// Waits for the script; prints its log.
    pub fn finish(mut self) -> Result<()> {
        let ok = self.child.wait()?.success();
        let log = std::fs::read_to_string(&self.log).unwrap_or_default();
        println!(
            "== {}: {}\n{}",
            self.what,
            if ok { "done" } else { "FAILED" },
            log.trim_end()
        );
        match ok {
            true => Ok(()),
            false => Err(format!("{} failed", self.what).into()),
        }
    }
}
