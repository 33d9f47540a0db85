//! Shared helpers of the HIL tests: where the firmware images are, built on
//! demand so `cargo test -p hil-tests` works on its own (xtask builds them
//! first anyway).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Once;

pub use taut_simavr as sim;

fn firmware_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware")
}

fn release_dir() -> PathBuf {
    firmware_dir().join("target/avr-none/release")
}

static BUILD: Once = Once::new();

/// Build the release image and the examples once per test process.
fn build() {
    BUILD.call_once(|| {
        let st = Command::new("cargo")
            .args(["build", "--release", "--bins", "--examples"])
            .current_dir(firmware_dir())
            .env_remove("RUSTUP_TOOLCHAIN")
            .env_remove("CARGO_TARGET_DIR")
            .status()
            .expect("cannot run cargo for the firmware");
        assert!(st.success(), "firmware build failed");
    });
}

/// The shipped firmware: the release ELF.
pub fn firmware_elf() -> PathBuf {
    build();
    release_dir().join("taut.elf")
}

/// A special-purpose image from `firmware/examples/NAME.rs`.
pub fn example_elf(name: &str) -> PathBuf {
    build();
    release_dir().join("examples").join(format!("{name}.elf"))
}

/// The version in firmware/Cargo.toml, which the banner must show.
pub fn firmware_version() -> String {
    let manifest = std::fs::read_to_string(firmware_dir().join("Cargo.toml")).unwrap();
    manifest
        .lines()
        .find_map(|l| l.strip_prefix("version = \""))
        .and_then(|v| v.strip_suffix('"'))
        .expect("version in firmware/Cargo.toml")
        .to_string()
}

/// Send one console line and panic (with the serial log) unless it is
/// answered `ok` within `timeout`.
pub fn send_ok(sim: &mut sim::Sim, line: &str, timeout: std::time::Duration) {
    match sim.send_line(line, timeout) {
        Ok(sim::Reply::Ok) => {}
        other => panic!("{line:?}: {other:?}\nUART: {}", sim.uart_text()),
    }
}
