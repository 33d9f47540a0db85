//! The serial port, raw at 115 200 baud (a Mega's USB serial or the
//! simulator's pseudo-terminal), its replies as lines from a reader thread;
//! and the keyboard in raw mode while a file streams (or SIGINT caught
//! when there is no keyboard).

use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Write};
use std::os::fd::AsRawFd;
use std::os::unix::fs::OpenOptionsExt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver};

pub struct Port {
    file: File,
    path: String,
}

impl Port {
    pub fn open(path: &str) -> Result<Port, String> {
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .custom_flags(libc::O_NOCTTY)
            .open(path)
            .map_err(|e| format!("{path}: {e}"))?;
        // SAFETY: a termios for the open descriptor, filled by tcgetattr
        // before use; nothing is kept past these calls.
        let ok = unsafe {
            let mut t: libc::termios = std::mem::zeroed();
            libc::tcgetattr(file.as_raw_fd(), &mut t) == 0 && {
                libc::cfmakeraw(&mut t);
                t.c_cflag |= libc::CLOCAL | libc::CREAD;
                libc::cfsetspeed(&mut t, libc::B115200) == 0
                    && libc::tcsetattr(file.as_raw_fd(), libc::TCSANOW, &t) == 0
            }
        };
        match ok {
            true => Ok(Port {
                file,
                path: path.into(),
            }),
            false => Err(format!("{path}: not a serial port")),
        }
    }

    pub fn write(&mut self, bytes: &[u8]) -> Result<(), String> {
        self.file
            .write_all(bytes)
            .map_err(|e| format!("{}: {e}", self.path))
    }

    /// The port's lines as they come (without line ends), from a thread.
    pub fn replies(&self) -> Result<Receiver<String>, String> {
        let reader = self.file.try_clone().map_err(|e| e.to_string())?;
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(reader).split(b'\n') {
                let Ok(line) = line else { break };
                let text = String::from_utf8_lossy(&line)
                    .trim_end_matches('\r')
                    .to_string();
                if tx.send(text).is_err() {
                    break;
                }
            }
        });
        Ok(rx)
    }
}

/// The terminal's mode before it was made raw, put back when dropped (on
/// every way out of a stream, a panic's unwinding included).
pub struct TermMode(libc::termios);

impl TermMode {
    /// Standard input one key at a time, without echo, if it is a
    /// terminal; the mode it had. Ctrl-C comes as a key (ISIG off), so a
    /// stop always sends Ctrl-X to the machine first.
    pub fn raw_stdin() -> Option<TermMode> {
        // SAFETY: termios structs filled by tcgetattr on fd 0; isatty first.
        unsafe {
            if libc::isatty(0) != 1 {
                return None;
            }
            let mut saved: libc::termios = std::mem::zeroed();
            if libc::tcgetattr(0, &mut saved) != 0 {
                return None;
            }
            let mut raw = saved;
            raw.c_lflag &= !(libc::ICANON | libc::ECHO | libc::ISIG);
            raw.c_cc[libc::VMIN] = 1;
            raw.c_cc[libc::VTIME] = 0;
            (libc::tcsetattr(0, libc::TCSANOW, &raw) == 0).then_some(TermMode(saved))
        }
    }
}

impl Drop for TermMode {
    fn drop(&mut self) {
        // SAFETY: puts back the mode tcgetattr gave for fd 0.
        unsafe { libc::tcsetattr(0, libc::TCSANOW, &self.0) };
    }
}

static INTERRUPTED: AtomicBool = AtomicBool::new(false);

extern "C" fn on_sigint(_: libc::c_int) {
    INTERRUPTED.store(true, Ordering::Relaxed);
}

/// Without a terminal (stdin piped), SIGINT still has to stop the machine:
/// it only raises a flag the stream loop reads as Ctrl-C.
pub fn catch_sigint() {
    let handler: extern "C" fn(libc::c_int) = on_sigint;
    // SAFETY: the handler only stores to an atomic (async-signal-safe).
    unsafe { libc::signal(libc::SIGINT, handler as libc::sighandler_t) };
}

/// Whether SIGINT came since the last call.
pub fn interrupted() -> bool {
    INTERRUPTED.swap(false, Ordering::Relaxed)
}
