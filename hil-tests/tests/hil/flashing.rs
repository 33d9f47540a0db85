//! Flashing as a maker does: a Mega 2560 holding only its stock
//! STK500v2 bootloader (Debian's `arduino-core-avr`), Debian's `avrdude`
//! writing the release image through the serial port exactly as ravedude
//! runs it, the bootloader starting taut, and what happens after a
//! watchdog reset, a write cut half way and a corrupt file.

use hil_tests::board::{self, avrdude, Board, Terminal, STOCK_BOOTLOADER};
use hil_tests::sim::{Outcome, Sim};
use std::path::Path;
use std::time::Duration;
use taut_trace::vcd;

/// STEP rises of a channel in a VCD.
fn rises(signals: &[vcd::Signal], name: &str) -> usize {
    let s = signals
        .iter()
        .find(|s| s.name == name)
        .unwrap_or_else(|| panic!("no {name} in the trace"));
    s.changes.iter().filter(|c| c.1).count()
}

#[test]
fn avrdude_writes_taut_through_the_stock_bootloader_and_taut_runs() {
    let dir = board::scratch("flash");
    let hex = board::hex_of(&hil_tests::firmware_elf(), &dir.join("taut.hex"));
    let mega = Board::power_on(&dir, None, &[]);

    let (out, ok, write_time) = avrdude(&mega.link, &[format!("-Uflash:w:{}:i", hex.display())]);
    assert!(ok, "avrdude write failed:\n{out}");
    assert!(
        out.contains("Device signature = 1E 98 01") || out.contains("1e9801"),
        "{out}"
    );
    assert!(
        out.contains("bytes of flash verified"),
        "the write's own verify:\n{out}"
    );
    let (out, ok, verify_time) = avrdude(&mega.link, &[format!("-Uflash:v:{}:i", hex.display())]);
    assert!(
        ok && out.contains("bytes of flash verified"),
        "verify:\n{out}"
    );
    eprintln!(
        "flashing: write + verify {:.1} s, verify alone {:.1} s (wall)",
        write_time.as_secs_f64(),
        verify_time.as_secs_f64()
    );

    // A terminal opens the port: the board resets, the bootloader waits
    // for avrdude, then starts taut.
    let mut term = Terminal::open(&mega.link);
    term.wait_for("Grbl 1.1h", Duration::from_secs(30));
    term.wait_for("reset:", Duration::from_secs(5));
    for line in ["G91", "G1 C15 X5 F3000", "G1 C-7.5 F3000", "M400"] {
        term.send_ok(line, Duration::from_secs(30));
    }
    drop(term);
    let (said, status) = mega.stop();
    assert!(status.success(), "taut-sim: {status}\n{said}");
    assert!(said.contains("ended: stopped by a signal"), "{said}");
    let signals = vcd::parse(&std::fs::read_to_string(dir.join("trace.vcd")).unwrap()).unwrap();
    // The default machine (the string-art one): C turns the base, X moves
    // the radial carriage, at their default steps per unit.
    use taut_logic::units::Milli;
    let cfg = taut_logic::config::MachineConfig::STRING_ART;
    let steps =
        |axis: usize, milli: i32| cfg.axes[axis].steps_per_unit.steps(Milli(milli)) as usize;
    let want_base = steps(0, 15_000) + (steps(0, 15_000) - steps(0, 7_500));
    let want_radial = steps(1, 5_000);
    let got = (rises(&signals, "base_step"), rises(&signals, "radial_step"));
    assert_eq!(got, (want_base, want_radial), "pulses of the moves");
    // Out of process, no end check of the simulation: the replay's.
    let trace = taut_trace::replay::Trace::from_signals(&signals, &cfg).unwrap();
    assert!(
        trace.steps_while_off().is_empty(),
        "stepped while off: {:?}",
        &trace.steps_while_off()[..trace.steps_while_off().len().min(5)]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A firmware whose task never returns, flashed through the bootloader:
/// the watchdog resets the board, the stock bootloader takes its watchdog
/// path (a call to word 0x10000, its EIND left at 1) into the firmware's
/// watchdog entry, and the firmware comes back saying `reset:watchdog`,
/// once per watchdog period: no loop inside the bootloader.
#[test]
fn after_a_watchdog_reset_the_bootloader_hands_back_to_the_firmware() {
    let dir = board::scratch("watchdog");
    let hex = board::hex_of(
        &hil_tests::example_elf("stuck_task"),
        &dir.join("stuck.hex"),
    );
    let mega = Board::power_on(&dir, None, &[]);
    let (out, ok, _) = avrdude(&mega.link, &[format!("-Uflash:w:{}:i", hex.display())]);
    assert!(ok, "{out}");
    let mut term = Terminal::open(&mega.link);
    term.wait_for("stuck_task reset:watchdog", Duration::from_secs(30));
    term.wait_for("task entering an endless loop", Duration::from_secs(10));
    let text = term.text();
    drop(term);
    let (said, _) = mega.stop();
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("report.json")).unwrap()).unwrap();
    // The open's reset went through the bootloader's wait: no flags left.
    assert!(text.contains("stuck_task reset:unknown"), "{text}");
    let boots = text.matches("stuck_task reset:").count() as u64;
    let watchdogs = report["watchdog_resets"].as_u64().unwrap();
    assert!(watchdogs >= 1, "{said}");
    assert!(
        boots >= watchdogs,
        "{watchdogs} watchdog resets, {boots} starts: the bootloader looped\n{text}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The release image already flashed: a task stuck for good (as a panic
/// leaves the MCU: `abort`'s endless loop) ends in a watchdog reset, and
/// the stock bootloader brings taut back, its banner saying why.
#[test]
fn taut_comes_back_through_the_bootloader_after_a_watchdog_reset() {
    let elf = hil_tests::firmware_elf();
    let mut sim = Sim::with_bootloader(Path::new(STOCK_BOOTLOADER), Some(&elf)).unwrap();
    // Power-on: the bootloader waits ~1 s for avrdude, then starts taut.
    // (The bootloader read and cleared the reset flags: no cause left.)
    let started = sim.run_until_uart_contains("reset:unknown", Duration::from_secs(3));
    assert_eq!(started, Outcome::Done, "{}", sim.uart_text());
    sim.run_for(Duration::from_millis(200));
    let abort = hil_tests::sim::elf::symbol_address(&elf, "abort")
        .unwrap()
        .expect("abort in the image");
    sim.jump_to(abort);
    let from = sim.uart_bytes().len();
    let reset = sim.run_for(Duration::from_secs(2));
    assert_eq!(reset, Outcome::WatchdogReset { count: 1 });
    let back = sim.run_until_uart_contains("reset:watchdog", Duration::from_secs(1));
    assert_eq!(back, Outcome::Done, "{}", sim.uart_text_from(from));
    assert!(sim.uart_text_from(from).contains("Grbl 1.1h"));
    // No second reset: it runs.
    assert_eq!(sim.run_for(Duration::from_secs(2)), Outcome::Running);
    assert_eq!(sim.watchdog_resets(), 1);
}

/// avrdude killed in the middle of the write: the next power-on does not
/// run half an image (taut's start-up finds its end missing and goes back
/// to the bootloader), and a second avrdude run writes it whole.
#[test]
fn a_write_cut_half_way_is_finished_by_the_next_avrdude() {
    let dir = board::scratch("cut-write");
    let hex = board::hex_of(&hil_tests::firmware_elf(), &dir.join("taut.hex"));
    let mega = Board::power_on(&dir, None, &[]);
    let mut child = std::process::Command::new("avrdude")
        .args(board::avrdude_args(&mega.link))
        .arg(format!("-Uflash:w:{}:i", hex.display()))
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Half way by avrdude's own progress bar: "Writing | ####…".
    let mut err = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut seen = Vec::new();
    let mut byte = [0u8; 1];
    while std::io::Read::read(&mut err, &mut byte).unwrap_or(0) == 1 {
        seen.push(byte[0]);
        let text = String::from_utf8_lossy(&seen);
        let writing = text.split("Writing").nth(1).unwrap_or("");
        if writing.matches('#').count() >= 25 {
            break;
        }
    }
    child.kill().unwrap();
    let _ = child.wait();
    // The board's next start: the bootloader waits for avrdude (1 s),
    // then the half image, which must not run.
    let mut term = Terminal::open(&mega.link);
    std::thread::sleep(Duration::from_secs(4));
    term.drain();
    assert!(
        !term.text().contains("Grbl"),
        "half an image ran: {}",
        term.text()
    );
    drop(term);
    let (out, ok, _) = avrdude(&mega.link, &[format!("-Uflash:w:{}:i", hex.display())]);
    assert!(ok, "the second write:\n{out}");
    let mut term = Terminal::open(&mega.link);
    term.wait_for("Grbl 1.1h", Duration::from_secs(30));
    drop(term);
    mega.stop();
    let _ = std::fs::remove_dir_all(&dir);
}

/// A hex file with a bad checksum: avrdude refuses it before it writes a
/// byte, and the board still runs what it had.
#[test]
fn a_corrupt_hex_file_is_refused_before_anything_is_written() {
    let dir = board::scratch("corrupt");
    let hex = board::hex_of(&hil_tests::firmware_elf(), &dir.join("taut.hex"));
    let mut text = std::fs::read_to_string(&hex).unwrap();
    // One data digit of the 100th record changed: its checksum is wrong.
    let line = text.lines().nth(100).unwrap().to_string();
    let mut bad = line.clone().into_bytes();
    bad[12] = if bad[12] == b'0' { b'1' } else { b'0' };
    text = text.replacen(&line, std::str::from_utf8(&bad).unwrap(), 1);
    let corrupt = dir.join("corrupt.hex");
    std::fs::write(&corrupt, text).unwrap();
    let mega = Board::power_on(&dir, Some(&hil_tests::firmware_elf()), &[]);
    let (out, ok, _) = avrdude(&mega.link, &[format!("-Uflash:w:{}:i", corrupt.display())]);
    assert!(!ok, "avrdude took a corrupt file:\n{out}");
    assert!(!out.contains("Writing"), "it wrote:\n{out}");
    let mut term = Terminal::open(&mega.link);
    term.wait_for("Grbl 1.1h", Duration::from_secs(30));
    drop(term);
    mega.stop();
    let _ = std::fs::remove_dir_all(&dir);
}

/// The maker's own command: `cargo run --release` in `firmware/`, cargo's
/// runner `ravedude` (firmware/.cargo/config.toml, firmware/Ravedude.toml)
/// pointed at the board's terminal with `RAVEDUDE_PORT`: it runs avrdude,
/// then opens the console, where taut greets.
#[test]
fn cargo_run_flashes_through_ravedude_and_opens_the_console() {
    use std::io::Read;
    use std::os::unix::process::CommandExt;
    use std::process::{Command, Stdio};
    if Command::new("ravedude").arg("--version").output().is_err() {
        panic!("ravedude is not installed: scripts/setup.sh installs it (cargo install ravedude)");
    }
    let dir = board::scratch("ravedude");
    let mega = Board::power_on(&dir, None, &[]);
    let firmware = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../firmware");
    let mut child = Command::new("cargo")
        .args(["run", "--release"])
        .current_dir(&firmware)
        .env("RAVEDUDE_PORT", &mega.link)
        .env_remove("RUSTUP_TOOLCHAIN")
        .env_remove("CARGO_TARGET_DIR")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .process_group(0)
        .spawn()
        .unwrap();
    // ravedude's console, read by a thread (a read blocks until it says
    // something); the build before it may wait for other builds' locks.
    let mut out = child.stdout.take().unwrap();
    let seen = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let into = seen.clone();
    std::thread::spawn(move || {
        let mut buf = [0u8; 256];
        while let Ok(n) = out.read(&mut buf) {
            if n == 0 {
                break;
            }
            into.lock().unwrap().extend_from_slice(&buf[..n]);
        }
    });
    let err = child.stderr.take().unwrap();
    let err = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = std::io::BufReader::new(err).read_to_string(&mut text);
        text
    });
    let start = std::time::Instant::now();
    let banner = |s: &[u8]| String::from_utf8_lossy(s).contains("Grbl 1.1h");
    while !banner(&seen.lock().unwrap()) && start.elapsed() < Duration::from_secs(900) {
        std::thread::sleep(Duration::from_millis(50));
    }
    // A signal to the process group this test made, as Ctrl-C would.
    let _ = Command::new("kill")
        .args(["-INT", "--", &format!("-{}", child.id())])
        .status();
    let _ = child.wait();
    let said = err.join().unwrap();
    mega.stop();
    let console = String::from_utf8_lossy(&seen.lock().unwrap()).into_owned();
    assert!(
        console.contains("Grbl 1.1h"),
        "no banner on ravedude's console after {:.0} s\nstdout:\n{console}\nstderr:\n{said}",
        start.elapsed().as_secs_f64()
    );
    assert!(
        said.contains("flash verified"),
        "avrdude under ravedude:\n{said}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
