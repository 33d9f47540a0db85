//! The simulated USART0 as a pseudo-terminal: host programs that open
//! `/dev/ttyACM0` (senders, terminals) open its path instead and talk to
//! the firmware as to a Mega on USB, in real time.
//!
//! The terminal is raw (no echo, no line-end translation), as a USB
//! serial port is. We keep the slave end open ourselves, so a client may
//! close and reopen it without the master seeing an end of file.

use crate::sim::Sim;
use std::ffi::CStr;
use std::fs::File;
use std::io::{self, Read, Write};
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

pub struct Pty {
    master: File,
    _slave: OwnedFd,
    path: PathBuf,
    link: Option<PathBuf>,
    /// UART bytes already written to the terminal.
    sent: usize,
    /// Wall time and simulated time when serving began: the pace.
    start: Option<(Instant, f64)>,
    /// Every byte the client wrote.
    received: Vec<u8>,
}

fn check(r: libc::c_int) -> io::Result<libc::c_int> {
    match r {
        -1 => Err(io::Error::last_os_error()),
        r => Ok(r),
    }
}

impl Pty {
    /// A new pseudo-terminal; `link`, if given, is made a symbolic link to
    /// its device (replacing a stale one).
    pub fn open(link: Option<&Path>) -> io::Result<Pty> {
        // SAFETY: plain libc calls on descriptors this function owns.
        unsafe {
            let master = check(libc::posix_openpt(libc::O_RDWR | libc::O_NOCTTY))?;
            let master = File::from_raw_fd(master);
            check(libc::grantpt(master.as_raw_fd()))?;
            check(libc::unlockpt(master.as_raw_fd()))?;
            let mut name = [0 as libc::c_char; 128];
            check(libc::ptsname_r(
                master.as_raw_fd(),
                name.as_mut_ptr(),
                name.len(),
            ))?;
            let path = PathBuf::from(
                CStr::from_ptr(name.as_ptr())
                    .to_str()
                    .map_err(io::Error::other)?,
            );
            let slave = check(libc::open(name.as_ptr(), libc::O_RDWR | libc::O_NOCTTY))?;
            let slave = OwnedFd::from_raw_fd(slave);
            let mut tio: libc::termios = std::mem::zeroed();
            check(libc::tcgetattr(slave.as_raw_fd(), &mut tio))?;
            libc::cfmakeraw(&mut tio);
            libc::cfsetspeed(&mut tio, libc::B115200);
            check(libc::tcsetattr(slave.as_raw_fd(), libc::TCSANOW, &tio))?;
            let flags = check(libc::fcntl(master.as_raw_fd(), libc::F_GETFL))?;
            check(libc::fcntl(
                master.as_raw_fd(),
                libc::F_SETFL,
                flags | libc::O_NONBLOCK,
            ))?;
            if let Some(link) = link {
                let _ = std::fs::remove_file(link);
                std::os::unix::fs::symlink(&path, link)?;
            }
            Ok(Pty {
                master,
                _slave: slave,
                path,
                link: link.map(Path::to_path_buf),
                sent: 0,
                start: None,
                received: Vec::new(),
            })
        }
    }

    /// The terminal device a client opens (`/dev/pts/N`).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Every byte the client wrote so far.
    pub fn received(&self) -> &[u8] {
        &self.received
    }

    /// Runs `sim` for `span` of simulated time, in step with the wall
    /// clock: what the client wrote goes to the UART first, what the UART
    /// sent goes to the client after.
    pub fn serve(&mut self, sim: &mut Sim, span: Duration) -> io::Result<()> {
        let (wall, sim_start) = *self.start.get_or_insert((Instant::now(), sim.time_s()));
        let mut buf = [0u8; 256];
        loop {
            match self.master.read(&mut buf) {
                Ok(0) => break,
                Ok(n) => {
                    sim.uart_send(&buf[..n]);
                    self.received.extend_from_slice(&buf[..n]);
                }
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => break,
                // No client has the terminal open (Linux reports EIO).
                Err(e) if e.raw_os_error() == Some(libc::EIO) => break,
                Err(e) => return Err(e),
            }
        }
        sim.run_for(span);
        let out = &sim.uart_bytes()[self.sent..];
        match self.master.write(out) {
            Ok(n) => self.sent += n,
            Err(e) if e.kind() == io::ErrorKind::WouldBlock => {}
            Err(e) if e.raw_os_error() == Some(libc::EIO) => self.sent += out.len(),
            Err(e) => return Err(e),
        }
        // Real time: never ahead of the wall clock.
        let ahead = (sim.time_s() - sim_start) - wall.elapsed().as_secs_f64();
        if ahead > 0.0 {
            std::thread::sleep(Duration::from_secs_f64(ahead));
        }
        Ok(())
    }
}

impl Drop for Pty {
    fn drop(&mut self) {
        if let Some(link) = &self.link {
            let _ = std::fs::remove_file(link);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs::OpenOptions;

    #[test]
    fn a_client_reads_and_writes_through_the_link() {
        let link = std::env::temp_dir().join(format!("taut-pty-test-{}", std::process::id()));
        let mut pty = Pty::open(Some(&link)).unwrap();
        assert_eq!(std::fs::read_link(&link).unwrap(), pty.path());
        let mut client = OpenOptions::new()
            .read(true)
            .write(true)
            .open(&link)
            .unwrap();
        client.write_all(b"?\n").unwrap();
        std::thread::sleep(Duration::from_millis(50));
        let mut got = [0u8; 8];
        let n = pty.master.read(&mut got).unwrap();
        assert_eq!(&got[..n], b"?\n", "raw: no echo, no translation");
        pty.master.write_all(b"ok\r\n").unwrap();
        let mut back = [0u8; 4];
        client.read_exact(&mut back).unwrap();
        assert_eq!(&back, b"ok\r\n");
        drop(pty);
        assert!(!link.exists());
    }
}
