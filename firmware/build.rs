//! Stamp the firmware with the git commit it was built from (for the
//! banner), let avr-gcc accept the `-no-pie` that rustc passes it, and
//! link avr-gcc's hand-written arithmetic in place of the Rust builtins.
//!
//! Rust's `compiler_builtins` defines the soft-float and wide-division
//! routines (`__mulsf3`, `__udivdi3`, …) as weak symbols written in
//! portable Rust: on the AVR an `f32` multiply costs ~1100 cycles, a
//! `u64` division several thousand. avr-libc's `libm.a` and avr-gcc's
//! `libgcc.a` hold the same routines in assembly (same ABI, several times
//! faster). Linked as objects, their strong definitions replace the weak
//! ones; an archive alone would not (a weak definition already satisfies
//! the reference). Their own helpers (`__fp_round`, …) come from the
//! archives as usual.
use std::path::{Path, PathBuf};
use std::process::Command;

/// Members of avr-libc's `libm.a`: single-precision arithmetic.
const LIBM: &[&str] = &[
    "addsf3.o",
    "mulsf3.o",
    "divsf3.o",
    "cmpsf2.o",
    "gesf2.o",
    "unordsf2.o",
    "fixsfsi.o",
    "fixunssfsi.o",
    "floatsisf.o",
    "fixsfdi.o",
    "floatdisf.o",
    "floatundisf.o",
];

/// Members of avr-gcc's `libgcc.a`: integer division. (The 64-bit
/// multiply is the image's own, `src/rt/mul64.rs`.)
const LIBGCC: &[&str] = &[
    "_udivmodhi4.o",
    "_divmodhi4.o",
    "_udivmodsi4.o",
    "_divmodsi4.o",
    "_udivdi3.o",
    "_divdi3.o",
];

/// Members of avr-libc's `libc.a`: memory routines LLVM calls (the Rust
/// ones copy a byte per loop turn; these are assembly, about three times
/// faster). `memcpy` and `memset`, called for every struct move and
/// clear, are the image's own (`src/rt/mem.S`).
const LIBC: &[&str] = &["memmove.o", "memcmp.o"];

/// The image's own assembly routines in `src/rt/`, each an object of
/// every image: the linker takes them before the builtins' weak portable
/// ones and instead of the archives' (the files say why each is there).
const OWN: &[&str] = &["mul64", "mem"];

fn main() {
    let hash = Command::new("git")
        .args(["describe", "--always", "--dirty", "--abbrev=8"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=TAUT_GIT_HASH={hash}");
    // The image's end mark (src/board/early.rs): a hash of every source
    // the image is built from, so a different build has a different mark.
    println!("cargo:rustc-env=TAUT_BUILD_MARK={}", source_hash());
    for dir in ["src", "logic/src", "progmem/src", "examples", "Cargo.lock"] {
        println!("cargo:rerun-if-changed={dir}");
    }
    // The commit (and `--dirty`) change with HEAD and the index: where git
    // keeps them, in a clone (`../.git/HEAD`) or a worktree (`.git` is a
    // file there). A path that does not exist would rerun this every build.
    for name in ["HEAD", "index"] {
        let at = Command::new("git")
            .args(["rev-parse", "--git-path", name])
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string());
        if let Some(at) = at.filter(|a| Path::new(a).exists()) {
            println!("cargo:rerun-if-changed={at}");
        }
    }

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
    println!("cargo:rerun-if-changed=build.rs");

    if std::env::var("CARGO_CFG_TARGET_ARCH").as_deref() != Ok("avr") {
        return;
    }
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    for (archive, members) in [
        (gcc_file("libm.a"), LIBM),
        (gcc_file("-libgcc"), LIBGCC),
        (gcc_file("libc.a"), LIBC),
    ] {
        extract(&archive, members, &out);
        for m in members {
            println!("cargo:rustc-link-arg={}", out.join(m).display());
        }
    }
    for name in OWN {
        let (src, obj) = (format!("src/rt/{name}.S"), out.join(format!("{name}.o")));
        let st = Command::new("avr-gcc")
            .args(["-mmcu=atmega2560", "-c", &src, "-o"])
            .arg(&obj)
            .status()
            .expect("avr-gcc (Debian gcc-avr) is needed to link the firmware");
        assert!(st.success(), "avr-gcc -c {src}");
        println!("cargo:rustc-link-arg={}", obj.display());
    }
    // After the objects: the archives are searched in order.
    println!("cargo:rustc-link-arg=-lm");
    println!("cargo:rustc-link-arg=-lgcc");
}

/// Where avr-gcc keeps `name` for the ATmega2560 (`-libgcc`: libgcc.a).
fn gcc_file(name: &str) -> PathBuf {
    let arg = match name {
        "-libgcc" => "-print-libgcc-file-name".to_string(),
        _ => format!("-print-file-name={name}"),
    };
    let o = Command::new("avr-gcc")
        .args(["-mmcu=atmega2560", &arg])
        .output()
        .expect("avr-gcc (Debian gcc-avr) is needed to link the firmware");
    PathBuf::from(String::from_utf8(o.stdout).unwrap().trim())
}

fn extract(archive: &Path, members: &[&str], into: &Path) {
    let st = Command::new("avr-ar")
        .arg("x")
        .arg(archive)
        .args(members)
        .current_dir(into)
        .status()
        .expect("avr-ar (Debian binutils-avr) is needed to link the firmware");
    assert!(st.success(), "avr-ar x {} {members:?}", archive.display());
}

/// FNV-1a (32 bits) over the sources' paths and bytes, in path order.
fn source_hash() -> u32 {
    fn walk(dir: &Path, files: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            files.push(dir.to_path_buf());
            return;
        };
        for e in entries.flatten() {
            let p = e.path();
            match p.is_dir() {
                true => walk(&p, files),
                false => files.push(p),
            }
        }
    }
    let mut files = Vec::new();
    for dir in ["src", "logic/src", "progmem/src", "examples", "Cargo.lock"] {
        walk(Path::new(dir), &mut files);
    }
    files.sort();
    let mut h: u32 = 0x811c_9dc5;
    for f in files {
        let bytes = std::fs::read(&f).unwrap_or_default();
        for b in f.to_string_lossy().bytes().chain(bytes) {
            h = (h ^ u32::from(b)).wrapping_mul(0x0100_0193);
        }
    }
    h
}
