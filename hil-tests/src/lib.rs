//! Shared helpers of the HIL tests: where the firmware images are, built on
//! demand so `cargo test -p hil-tests` works on its own (xtask builds them
//! first anyway).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Once;

pub use taut_simavr as sim;

pub mod board;
pub mod drawing;
pub mod drivers;
pub mod feed;
pub mod reference;
pub mod senders;

/// A host tool of this workspace (`taut`, `taut-sim`), its debug binary.
/// Built once per test process, as `cargo test --workspace` builds it: the
/// same packages selected, so the same features, and nothing is compiled
/// again when that run (`cargo xtask test`) has built it already; a build
/// of one package alone would compile its dependencies a second time with
/// fewer features.
pub fn host_bin(name: &str) -> PathBuf {
    static BUILT: Once = Once::new();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    BUILT.call_once(|| {
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let st = Command::new(cargo)
            // The binaries of the packages with integration tests: what
            // `cargo test --workspace` builds (with `--bins`, xtask's too,
            // and the next `cargo xtask` would build its own again).
            .args(["build", "--quiet", "--workspace", "--tests"])
            .current_dir(&root)
            .status()
            .expect("cannot run cargo");
        assert!(st.success(), "building the host tools failed");
    });
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"))
        .join("debug")
        .join(name)
}

/// A tiny seeded generator (xorshift): the same draws on every run.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }

    /// Uniform in `lo..hi`.
    pub fn between(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `full` under `cargo xtask soak` (`TAUT_SOAK=1`), `everyday` otherwise.
pub fn soak_or<T>(full: T, everyday: T) -> T {
    match std::env::var_os("TAUT_SOAK") {
        Some(_) => full,
        None => everyday,
    }
}

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

/// Static RAM plus the deepest stack seen stays within 5.5 KiB of the 8:
/// the rest is headroom for what the tests do not reach.
pub const RAM_BUDGET: u32 = 5632;

/// With `TAUT_STACK_CHAINS` set (`cargo xtask test` sets it), the call
/// chain at the test's deepest stack goes to `target/hil-stack-chains.txt`
/// (`stack_chain`): the whole run's deep paths, for RAM work.
fn record_chain(sim: &sim::Sim, test: &str) {
    // The release image's code, read once per test binary.
    static CODE: std::sync::OnceLock<sim::stack_chain::Code> = std::sync::OnceLock::new();
    let Some(stack) = sim.peak_stack() else {
        return;
    };
    let code = CODE.get_or_init(|| sim::stack_chain::Code::read(&firmware_elf()));
    let mut text = format!("{test} {} B\n", sim.peak_stack_bytes());
    for frame in code.chain(stack, sim.peak_stack_pc()) {
        text += &format!("  {:>5} {:>4}  {}\n", frame.depth, frame.bytes, frame.at);
    }
    append("hil-stack-chains.txt", &text);
}

/// Adds `text` to `target/NAME`, the whole run's record.
fn append(name: &str, text: &str) {
    let log = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../target")
        .join(name);
    if let Ok(mut f) = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(log)
    {
        let _ = f.write_all(text.as_bytes());
    }
}

/// Checked at the end of every HIL test that runs the release image.
/// Each test's figure is also added to `target/hil-stack-peaks.txt` (test,
/// stack bytes, where), to find the deepest path of a whole run.
pub fn assert_ram_budget(sim: &sim::Sim) {
    let statics = sim.elf().unwrap().ram_static_bytes();
    let stack = sim.peak_stack_bytes() as u32;
    let test = std::thread::current().name().unwrap_or("?").to_string();
    let peak = format!("{test} {stack} {:#x}\n", sim.peak_stack_pc());
    append("hil-stack-peaks.txt", &peak);
    record_chain(sim, &test);
    assert!(
        statics + stack <= RAM_BUDGET,
        "static {statics} B + stack {stack} B = {} B, over the {RAM_BUDGET} B budget; \
         deepest at {:#x} (avr-addr2line -fe taut.elf; the call chain: target/hil-stack-chains.txt)",
        statics + stack,
        sim.peak_stack_pc()
    );
}

/// A FAT card image holding `files` (name, contents).
pub fn card(files: &[(&str, &[u8])]) -> sim::sdcard::SdImage {
    static N: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let n = N.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("taut-hil-card-{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (name, bytes) in files {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    let image = sim::sdcard::SdImage::from_dir(&dir, sim::sdimage::FatChoice::Auto).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    image
}

/// The sample job of `examples/card/` (hexagon, 24 nails, 30 connections).
pub fn sample_card_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/card")
}

/// The release image with every machine pin probed under its VCD name
/// (`<axis>_step|dir|en`, `x_in1`..`z_in4`, `btn_<button>`, `pen_pwm`),
/// booted; its drivers checked when it ends (`drivers`).
pub fn boot_machine() -> sim::Sim {
    let mut sim = machine();
    let booted = sim.run_until_uart_contains("reset:", std::time::Duration::from_millis(50));
    assert_eq!(booted, sim::Outcome::Done);
    sim
}

/// The release image with every machine pin probed, not yet run: fit
/// end-stops or load an EEPROM first.
pub fn machine() -> sim::Sim {
    use taut_logic::axis::Axis;
    use taut_logic::pinmap::{self, Button};
    let mut sim = load();
    for axis in [Axis::Base, Axis::Radial, Axis::Drill] {
        let d = pinmap::driver(axis);
        sim.probe_step_dir(axis.name(), d.step, d.dir, true);
        sim.probe(d.enable, &format!("{}_en", axis.name()));
    }
    sim.probe_coils();
    sim.probe(pinmap::PEN_SERVO, "pen_pwm");
    for b in Button::ALL {
        sim.release(b.pin());
        sim.probe(b.pin(), &format!("btn_{}", b.name()));
    }
    sim
}

/// The flatbed chosen on a first boot (kept in EEPROM), then the release
/// image again with that EEPROM and the flatbed's X switch `at` steps from
/// where X stands, not yet run: it homes X against it at power-on.
pub fn flatbed_with_x_switch(at: i64) -> sim::Sim {
    use taut_logic::axis::Axis;
    use taut_logic::pinmap::{driver, Button};
    let eeprom = {
        let mut sim = boot_machine();
        send_ok(
            &mut sim,
            "$machine=flatbed",
            std::time::Duration::from_secs(2),
        );
        sim.run_for(std::time::Duration::from_secs(2));
        sim.eeprom()
    };
    let mut sim = machine();
    sim.set_eeprom(&eeprom);
    let x = driver(Axis::Base);
    sim.endstop(Button::ZeroBase.pin(), x.step, x.dir, true, at);
    sim
}

/// The release image, nothing probed yet, not run; its drivers checked
/// when it ends ([`drivers::check_at_end`]: probe STEP, DIR and ENABLE of
/// any driver it moves).
pub fn load() -> sim::Sim {
    let mut sim = sim::Sim::load(&firmware_elf()).unwrap();
    drivers::check_at_end(&mut sim);
    sim
}

/// STEP pulses on `axis` so far, counted on its probe.
pub fn pulses(sim: &sim::Sim, axis: taut_logic::axis::Axis) -> usize {
    sim.probed(&format!("{}_step", axis.name()))
        .edges()
        .iter()
        .filter(|e| e.high)
        .count()
}

/// Run until the serial log contains `text`; panic with the log otherwise.
pub fn wait_for(sim: &mut sim::Sim, text: &str, timeout: std::time::Duration) {
    let end = sim.run_until_uart_contains(text, timeout);
    assert_eq!(
        end,
        sim::Outcome::Done,
        "waiting for {text:?}:\n{}",
        sim.uart_text()
    );
}

/// Timer3 COMPA vector (byte address): the step interrupt.
pub const STEP_VECTOR: u32 = 0x80;
/// Documented bound (docs/architecture.md): no code masks the step interrupt longer.
pub const MASKED_BOUND_CYCLES: u64 = 80;

/// Nothing (the card driver, the job, the console…) kept the step
/// interrupt masked longer than the documented bound.
pub fn assert_step_interrupt_never_masked_long(sim: &sim::Sim) {
    let (masked, at) = sim.max_masked_cycles(STEP_VECTOR);
    assert!(
        masked <= MASKED_BOUND_CYCLES,
        "interrupts masked {masked} cycles at {at:#x}"
    );
}

/// Net steps of the three machine axes (base, radial, drill) counted on
/// their STEP and DIR pins.
pub fn steps_on_pins(sim: &sim::Sim) -> [i64; 3] {
    use taut_logic::axis::Axis;
    [Axis::Base, Axis::Radial, Axis::Drill].map(|axis| {
        let d = taut_logic::pinmap::driver(axis);
        sim.net_steps(d.step, d.dir, true)
    })
}

/// The executed position `M114` reports, in steps (`Count C:… X:… Z:…`).
pub fn reported_steps(sim: &mut sim::Sim) -> [i64; 3] {
    let start = sim.uart_bytes().len();
    send_ok(sim, "M114", std::time::Duration::from_secs(1));
    m114_counts(&sim.uart_text_from(start))
}

/// The steps of `M114`'s `Count X:… Y:… Z:…` in `text`.
pub fn m114_counts(text: &str) -> [i64; 3] {
    let count = text
        .lines()
        .find_map(|l| l.split_once("Count "))
        .unwrap_or_else(|| panic!("no M114 line in {text:?}"))
        .1;
    let mut out = [0; 3];
    for (i, word) in count.split_whitespace().take(3).enumerate() {
        out[i] = word[2..].parse().unwrap();
    }
    out
}

/// Whether a console line is one of taut's log lines (`[MSG:I 1234
/// module: …]`), not a reply; Grbl's own messages (`[MSG:Caution: …]`)
/// are replies.
pub fn is_log_line(l: &str) -> bool {
    let b = l.as_bytes();
    l.starts_with("[MSG:") && b.get(6) == Some(&b' ') && b.get(7).is_some_and(u8::is_ascii_digit)
}

/// The last 2000 characters of the serial log, for failure messages.
pub fn log_tail(sim: &sim::Sim) -> String {
    let t = sim.uart_text();
    let mut from = t.len().saturating_sub(2000);
    while !t.is_char_boundary(from) {
        from += 1;
    }
    t[from..].to_string()
}

/// Highest acceleration of a pulse train, steps/s²: speeds from windows of
/// `window` pulses, then the change between windows. Exact for uniform
/// acceleration and insensitive to the ±1 µs placement of single pulses.
pub fn max_accel(rises: &[u64], window: usize) -> f64 {
    let t: Vec<f64> = rises.iter().map(|&c| c as f64 / 16e6).collect();
    let mut prev: Option<(f64, f64)> = None;
    let mut max: f64 = 0.0;
    for i in (0..t.len().saturating_sub(window)).step_by(window) {
        let (t0, t1) = (t[i], t[i + window]);
        let v = window as f64 / (t1 - t0);
        let mid = (t0 + t1) / 2.0;
        if let Some((pv, pm)) = prev {
            max = max.max(((v - pv) / (mid - pm)).abs());
        }
        prev = Some((v, mid));
    }
    max
}

/// Rising-edge cycles of a probed STEP pin.
pub fn rising(sim: &sim::Sim, name: &str) -> Vec<u64> {
    sim.probed(name)
        .edges()
        .iter()
        .filter(|e| e.high)
        .map(|e| e.cycle)
        .collect()
}

/// STEP pulses of the three machine axes so far.
pub fn all_pulses(sim: &sim::Sim) -> [usize; 3] {
    use taut_logic::axis::Axis;
    [Axis::Base, Axis::Radial, Axis::Drill].map(|a| pulses(sim, a))
}

/// Runs until no axis has stepped for a second (at most 30 s): the pulse
/// counts then.
pub fn settle(sim: &mut sim::Sim) -> [usize; 3] {
    let mut last = all_pulses(sim);
    for _ in 0..30 {
        sim.run_for(std::time::Duration::from_secs(1));
        let now = all_pulses(sim);
        if now == last {
            return now;
        }
        last = now;
    }
    panic!("still moving after 30 s:\n{}", sim.uart_text());
}

/// Hold `button` for `ms`, release it, then 100 ms for it to settle.
pub fn press(sim: &mut sim::Sim, button: taut_logic::pinmap::Button, ms: u64) {
    sim.press(button.pin());
    sim.run_for(std::time::Duration::from_millis(ms));
    sim.release(button.pin());
    sim.run_for(std::time::Duration::from_millis(100));
}

/// The machine's path rebuilt from its STEP and DIR pins alone, and from
/// its coil inputs where they are probed (a 28BYJ-48's half-steps, phase
/// up positive): after every step of any of the three axes (base, radial,
/// drill), its cycle and the three step counts then.
pub fn track(sim: &sim::Sim) -> Vec<(u64, [i64; 3])> {
    use taut_logic::axis::Axis;
    let mut steps: Vec<(u64, usize, i64)> = Vec::new();
    for (i, axis) in [Axis::Base, Axis::Radial, Axis::Drill]
        .into_iter()
        .enumerate()
    {
        let step = sim.probed(&format!("{}_step", axis.name()));
        let dir = sim.probed(&format!("{}_dir", axis.name()));
        for e in step.edges().iter().filter(|e| e.high) {
            steps.push((e.cycle, i, if dir.level_at(e.cycle) { 1 } else { -1 }));
        }
        if sim.probes().iter().any(|p| p.name() == "x_in1") {
            let mut last = 0;
            for (cycle, pos) in sim.coil_track(i).steps {
                steps.push((cycle, i, pos - last));
                last = pos;
            }
        }
    }
    steps.sort_unstable();
    let mut at = [0i64; 3];
    steps
        .into_iter()
        .map(|(cycle, i, d)| {
            at[i] += d;
            (cycle, at)
        })
        .collect()
}

/// The pen servo's angle at `cycle`, degrees, from the last whole pulse
/// on `pen_pwm` before it (1–2 ms for 0–180°); `None` before any.
pub fn pen_deg_at(sim: &sim::Sim, cycle: u64) -> Option<f64> {
    let edges = sim.probed("pen_pwm").edges();
    let end = edges.partition_point(|e| e.cycle <= cycle);
    let fall = edges[..end].iter().rposition(|e| !e.high)?;
    let rise = edges[..fall].iter().rposition(|e| e.high)?;
    let us = (edges[fall].cycle - edges[rise].cycle) as f64 / 16.0;
    Some((us - 1000.0) * 180.0 / 1000.0)
}

/// A string-art card's `machine.txt` with coarser steps and quicker ramps
/// than the defaults: a job's moves in an eighth of the pulses and a tenth
/// of the time, so jobs cut again and again simulate in CI's time.
pub const QUICK_MACHINE_TXT: &str = "base_steps_per_unit = 1200/360\nradial_steps_per_unit = 4\n\
    drill_steps_per_unit = 200/12\nbase_accel = 8000\nradial_accel = 8000\ndrill_accel = 8000\n";

/// The string-art machine as a card with [`QUICK_MACHINE_TXT`] sets it
/// up: what its pulses are read with.
pub fn quick_string_art() -> taut_logic::config::MachineConfig {
    let mut cfg = taut_logic::config::MachineConfig::STRING_ART;
    for line in QUICK_MACHINE_TXT.lines() {
        let (key, value) = line.split_once('=').unwrap();
        taut_logic::settings::set(&mut cfg, key.trim(), value.trim()).unwrap();
    }
    cfg
}
