//! A Mega with its stock bootloader, as `taut-sim --bootloader HEX --pty
//! LINK` serves it, and the real tools that flash it: Debian's `avrdude`
//! (as ravedude runs it) and `ravedude` itself.

use std::io::{BufRead, BufReader, Read};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Debian's `arduino-core-avr`: the bootloader every Arduino Mega 2560
/// ships with.
pub const STOCK_BOOTLOADER: &str =
    "/usr/share/arduino/hardware/arduino/avr/bootloaders/stk500v2/stk500boot_v2_mega2560.hex";

/// avrdude's arguments for a Mega 2560 on `port`, as ravedude gives them
/// (its `mega2560` board: the `wiring` programmer, 115200 baud, no chip
/// erase: the bootloader erases each page it writes).
pub fn avrdude_args(port: &Path) -> Vec<String> {
    [
        "-c",
        "wiring",
        "-p",
        "atmega2560",
        "-b",
        "115200",
        "-D",
        "-P",
    ]
    .iter()
    .map(|s| s.to_string())
    .chain([port.display().to_string()])
    .collect()
}

/// The `taut-sim` binary.
pub fn taut_sim() -> PathBuf {
    crate::host_bin("taut-sim")
}

/// A folder of this test's own under the temporary directory.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("taut-hil-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The Intel hex of an ELF, as `cargo xtask build` makes it.
pub fn hex_of(elf: &Path, out: &Path) -> PathBuf {
    let st = Command::new("avr-objcopy")
        .args(["-O", "ihex", "-R", ".eeprom"])
        .arg(elf)
        .arg(out)
        .status()
        .expect("avr-objcopy (binutils-avr)");
    assert!(st.success());
    out.to_path_buf()
}

/// `taut-sim --bootloader` running in its own process group.
pub struct Board {
    child: Child,
    pub link: PathBuf,
    pub dir: PathBuf,
    /// What taut-sim said on stderr, read by a thread.
    stderr: std::thread::JoinHandle<String>,
}

impl Board {
    /// Powers on a Mega holding only the stock bootloader (and `app`, an
    /// ELF already flashed, if given), its port on `dir/ttyMEGA`.
    pub fn power_on(dir: &Path, app: Option<&Path>, extra: &[&str]) -> Board {
        let link = dir.join("ttyMEGA");
        let mut cmd = Command::new(taut_sim());
        if let Some(app) = app {
            cmd.arg(app);
        }
        cmd.args(["--bootloader", STOCK_BOOTLOADER, "--pty"])
            .arg(&link)
            .args(["--vcd"])
            .arg(dir.join("trace.vcd"))
            .args(["--report"])
            .arg(dir.join("report.json"))
            .args(extra)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .process_group(0);
        let mut child = cmd.spawn().expect("taut-sim");
        let mut err = BufReader::new(child.stderr.take().unwrap());
        let mut first = String::new();
        err.read_line(&mut first).unwrap();
        assert!(first.contains("serial port on"), "taut-sim: {first}");
        let stderr = std::thread::spawn(move || {
            let mut rest = first;
            let _ = err.read_to_string(&mut rest);
            rest
        });
        Board {
            child,
            link,
            dir: dir.to_path_buf(),
            stderr,
        }
    }

    /// SIGINT to the board's process group (as Ctrl-C in its terminal):
    /// it writes the trace and the report and ends. Returns its stderr
    /// and exit status.
    pub fn stop(mut self) -> (String, std::process::ExitStatus) {
        // SAFETY: a signal to the process group this test made.
        unsafe { libc_kill(-(self.child.id() as i32), 2) };
        let status = self.child.wait().unwrap();
        (self.stderr.join().unwrap(), status)
    }
}

extern "C" {
    #[link_name = "kill"]
    fn libc_kill(pid: i32, sig: i32) -> i32;
}

/// A client of the board's port (a terminal): opening it resets the board.
pub struct Terminal {
    file: std::fs::File,
    pub seen: Vec<u8>,
}

impl Terminal {
    pub fn open(link: &Path) -> Terminal {
        use std::os::unix::fs::OpenOptionsExt;
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .custom_flags(0o4000) // O_NONBLOCK
            .open(link)
            .unwrap();
        Terminal {
            file,
            seen: Vec::new(),
        }
    }

    /// Reads until the text holds `want`, or panics after `timeout` of
    /// wall time with what came.
    pub fn wait_for(&mut self, want: &str, timeout: Duration) {
        let end = Instant::now() + timeout;
        let mut buf = [0u8; 512];
        loop {
            if String::from_utf8_lossy(&self.seen).contains(want) {
                return;
            }
            assert!(
                Instant::now() < end,
                "no {want:?} within {timeout:?}; got:\n{}",
                String::from_utf8_lossy(&self.seen)
            );
            match self.file.read(&mut buf) {
                Ok(n) => self.seen.extend_from_slice(&buf[..n]),
                Err(_) => std::thread::sleep(Duration::from_millis(5)),
            }
        }
    }

    /// Sends a line and waits for its `ok`.
    pub fn send_ok(&mut self, line: &str, timeout: Duration) {
        use std::io::Write;
        // `ok` lines, whatever line ends the terminal's settings give.
        let count = |seen: &[u8]| {
            String::from_utf8_lossy(seen)
                .lines()
                .filter(|l| l.trim() == "ok")
                .count()
        };
        let oks = count(&self.seen);
        self.file.write_all(format!("{line}\n").as_bytes()).unwrap();
        let end = Instant::now() + timeout;
        let mut buf = [0u8; 512];
        while count(&self.seen) <= oks {
            assert!(
                Instant::now() < end,
                "{line}: no ok; got:\n{}",
                String::from_utf8_lossy(&self.seen)
            );
            match self.file.read(&mut buf) {
                Ok(n) => self.seen.extend_from_slice(&buf[..n]),
                Err(_) => std::thread::sleep(Duration::from_millis(5)),
            }
        }
    }

    /// Reads what has arrived.
    pub fn drain(&mut self) {
        let mut buf = [0u8; 512];
        while let Ok(n) = self.file.read(&mut buf) {
            if n == 0 {
                break;
            }
            self.seen.extend_from_slice(&buf[..n]);
        }
    }

    pub fn text(&self) -> String {
        String::from_utf8_lossy(&self.seen).into_owned()
    }
}

/// avrdude (as ravedude runs it) with `ops` (`-U …`), its output and
/// status, and how long it took.
pub fn avrdude(port: &Path, ops: &[String]) -> (String, bool, Duration) {
    let start = Instant::now();
    let out = Command::new("avrdude")
        .args(avrdude_args(port))
        .args(ops)
        .output()
        .expect("avrdude (Debian package; scripts/setup.sh installs it)");
    let text =
        String::from_utf8_lossy(&out.stderr).into_owned() + &String::from_utf8_lossy(&out.stdout);
    (text, out.status.success(), start.elapsed())
}
