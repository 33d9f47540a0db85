//! Stamp the firmware with the git commit it was built from (for the banner),
//! and let avr-gcc accept the `-no-pie` that rustc passes it.
use std::path::Path;
use std::process::Command;

fn main() {
    let hash = Command::new("git")
        .args(["describe", "--always", "--dirty", "--abbrev=8"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=TAUT_GIT_HASH={hash}");
    println!("cargo:rerun-if-changed=../.git/HEAD");
    println!("cargo:rerun-if-changed=../.git/index");

    // rustc links every executable for a GNU cc-style linker with `-no-pie`
    // (avr-none: linker avr-gcc, flavor gnu-cc, static relocation). avr-gcc 5
    // (Debian's gcc-avr) predates that option: the link fails, and rustc
    // retries without it, logging `WARN rustc_codegen_ssa::back::link Linker
    // does not support -no-pie command line option. Retrying without.` on
    // every link. A spec file that names the option makes the driver accept
    // it (GCC validates unknown switches against the specs); it adds nothing
    // to the link, which on AVR is never position-independent anyway. Newer
    // avr-gcc knows `-no-pie` itself and reads the same file harmlessly.
    let specs = Path::new(&std::env::var("CARGO_MANIFEST_DIR").unwrap()).join("no-pie.specs");
    println!("cargo:rustc-link-arg=-specs={}", specs.display());
    println!("cargo:rerun-if-changed=no-pie.specs");
}
