//! Building and flashing the AVR firmware (its own cargo workspace).

use crate::run::{cargo, cargo_cmd, root, status, Result};
use std::path::PathBuf;
use std::process::Command;

/// Flash the firmware may use: 224 KiB of the 256, the bootloader owns
/// the top.
pub const FLASH_BUDGET: u64 = crate::flashmap::BUDGET;
/// Static RAM plus the deepest stack a HIL test sees: 5.5 KiB of the 8
/// (the same bar as `hil_tests::RAM_BUDGET`, which each test checks).
pub const RAM_BUDGET: u64 = 5_632;

pub struct Image {
    pub elf: PathBuf,
    pub hex: PathBuf,
    pub flash_bytes: u64,
    pub ram_static_bytes: u64,
    pub data_bytes: u64,
    pub map: crate::flashmap::FlashMap,
}

pub fn dir() -> PathBuf {
    root().join("firmware")
}

pub fn release_dir() -> PathBuf {
    dir().join("target/avr-none/release")
}

pub fn build_release() -> Result<Image> {
    println!("== building the firmware (avr-none, release)");
    cargo(&["build", "--release"], &dir())?;
    let elf = release_dir().join("taut.elf");
    let hex = release_dir().join("taut.hex");
    status(
        Command::new("avr-objcopy")
            .args(["-O", "ihex", "-R", ".eeprom"])
            .arg(&elf)
            .arg(&hex),
    )?;
    let sizes = section_sizes(&elf)?;
    let get = |n: &str| sizes.iter().find(|(s, _)| s == n).map_or(0, |(_, v)| *v);
    let map = crate::flashmap::check(&elf)?;
    let img = Image {
        flash_bytes: get(".text") + get(".data") + get(".endmark"),
        map,
        ram_static_bytes: get(".data") + get(".bss") + get(".noinit"),
        data_bytes: get(".data"),
        elf,
        hex,
    };
    if img.flash_bytes > FLASH_BUDGET {
        img.print_size();
        return Err(format!(
            "flash {} B is over the {FLASH_BUDGET} B budget (the bootloader owns the top)",
            img.flash_bytes
        )
        .into());
    }
    Ok(img)
}

/// The firmware's lints: unsafe code only in `rt/`, `board/` and
/// `stepper/` (`unsafe_code`, denied at the crate root), each unsafe block
/// with its SAFETY note, and clippy clean.
pub fn lint() -> Result<()> {
    println!("== firmware lints (clippy, unsafe code)");
    cargo(
        &[
            "clippy",
            "--release",
            "--quiet",
            "--lib",
            "--bin",
            "taut",
            "--",
            "-D",
            "warnings",
            "-D",
            "clippy::undocumented_unsafe_blocks",
        ],
        &dir(),
    )
}

/// The special-purpose images in firmware/examples (crash, hang, …).
/// Those built on the firmware's crate (its start-up, its runtime) have
/// their flash map checked like the firmware's (the watchdog entry, the
/// end mark); the bare ones (blink, crash, …) test the simulator alone
/// and are never flashed through the bootloader.
pub fn build_examples() -> Result<()> {
    println!("== building the example images");
    cargo(&["build", "--release", "--examples"], &dir())?;
    for e in std::fs::read_dir(dir().join("examples"))? {
        let src = e?.path();
        let Some(name) = src.file_stem().and_then(|s| s.to_str()) else {
            continue;
        };
        if src.extension().is_some_and(|x| x == "rs")
            && std::fs::read_to_string(&src)?.contains("taut_firmware::")
        {
            crate::flashmap::check(&release_dir().join(format!("examples/{name}.elf")))?;
        }
    }
    Ok(())
}

pub fn flash() -> Result<()> {
    let img = build_release()?;
    img.print_size();
    println!(
        "== flashing through ravedude (Mega 2560 on the first serial port it finds, \
         or RAVEDUDE_PORT)"
    );
    let mut c = cargo_cmd(&["run", "--release"], &dir());
    status(&mut c)
}

impl Image {
    pub fn print_size(&self) {
        println!(
            "size: flash {} B of the {FLASH_BUDGET} B budget ({:.1} %), static RAM {} B of 8192 (.data {} B)\n      {}\n      {}",
            self.flash_bytes,
            100.0 * self.flash_bytes as f64 / FLASH_BUDGET as f64,
            self.ram_static_bytes,
            self.data_bytes,
            self.elf.display(),
            self.hex.display()
        );
        self.map.print();
    }
}

/// Allocated section sizes, from `avr-size -A`.
fn section_sizes(elf: &PathBuf) -> Result<Vec<(String, u64)>> {
    let out = Command::new("avr-size").arg("-A").arg(elf).output()?;
    let text = String::from_utf8_lossy(&out.stdout);
    Ok(text
        .lines()
        .filter_map(|l| {
            let mut f = l.split_whitespace();
            let name = f.next()?;
            let size = f.next()?.parse().ok()?;
            name.starts_with('.').then(|| (name.to_string(), size))
        })
        .collect())
}
