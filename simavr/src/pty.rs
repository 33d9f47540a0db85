//! The simulated USART0 as a pseudo-terminal: host programs that open
//! `/dev/ttyACM0` (senders, terminals) open its path instead and talk to
//! the firmware as to a Mega on USB, in real time. USART1 (the second
//! console, a Bluetooth module's `/dev/rfcomm0`) may have one too,
//! served with it ([`Pty::serve_uart1`]).
//!
//! The terminal is raw (no echo, no line-end translation), as a USB
//! serial port is. We keep the slave end open ourselves, so a client may
//! close and reopen it without the master seeing an end of file.
//!
//! A Mega resets when a host opens its port: the USB chip asserts DTR,
//! and the auto-reset capacitor turns that edge into a pulse on RESET.
//! A pseudo-terminal has no modem lines (avrdude's and ravedude's DTR/RTS
//! ioctls fail on it, which they report and go on), but opening it can be
//! seen: inotify reports every `open` of the slave's device node
//! ([`Pty::reset_on_open`]). That is the edge the capacitor passes on a
//! real board too: DTR asserted on open. (avrdude's later DTR release and
//! re-assert, 50 ms apart, would give a second pulse on a real board: the
//! bootloader starts again 50 ms later, which changes nothing it sees.)
//!
//! Pace: by default simulated time never runs ahead of the wall clock
//! ([`Pace::RealTime`]). [`Pace::BusyLink`] lets it run as fast as the host
//! can simulate while bytes are on the line in either direction, and holds
//! it to the wall clock again whenever the line is idle: every wait the
//! MCU sees for the host is as long as the host took, every byte still
//! takes its 86.8 µs of simulated time at 115200 baud, and a transfer of
//! 180 KB takes seconds instead of the line's 16 s each way.

use crate::clock::cycles_in;
use crate::sim::Sim;
use crate::Outcome;
use std::ffi::CStr;
use std::fs::File;
use std::io::{self, Read, Write};
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// How simulated time keeps pace with the wall clock while serving.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Pace {
    /// Never ahead of the wall clock.
    #[default]
    RealTime,
    /// As fast as the host can go while bytes are on the line; real time
    /// while it is idle.
    BusyLink,
}

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
    /// inotify on the slave's device node, when an open resets the board.
    opens: Option<OwnedFd>,
    pace: Pace,
    /// The USART this terminal is: USART1 rather than USART0.
    uart1: bool,
    /// USART1's terminal, served along with this one.
    second: Option<Box<Pty>>,
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
            // Close-on-exec, both ends: a process another thread spawns
            // meanwhile (a test binary runs tests side by side) would keep
            // a copy, and the terminal would not hang up when the
            // simulator ends (the client would never see its link lost).
            let master = check(libc::posix_openpt(
                libc::O_RDWR | libc::O_NOCTTY | libc::O_CLOEXEC,
            ))?;
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
            let slave = check(libc::open(
                name.as_ptr(),
                libc::O_RDWR | libc::O_NOCTTY | libc::O_CLOEXEC,
            ))?;
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
                opens: None,
                pace: Pace::RealTime,
                uart1: false,
                second: None,
            })
        }
    }

    /// Serve `uart1` (a terminal [`Pty::open`] made) as USART1's, along
    /// with this one: what its client writes goes to USART1, what USART1
    /// sends to it. No reset on its open: a Bluetooth link has no DTR.
    pub fn serve_uart1(&mut self, mut uart1: Pty) {
        uart1.uart1 = true;
        self.second = Some(Box::new(uart1));
    }

    /// The terminal device a client opens (`/dev/pts/N`).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Every byte the client wrote so far.
    pub fn received(&self) -> &[u8] {
        &self.received
    }

    /// From now on, each `open` of the terminal by a client resets the
    /// board ([`Sim::reset_external`]) before the next span runs, as a
    /// Mega's auto-reset does when a host opens its port.
    pub fn reset_on_open(&mut self) -> io::Result<()> {
        let path = std::ffi::CString::new(self.path.as_os_str().as_encoded_bytes())
            .map_err(io::Error::other)?;
        // SAFETY: plain libc calls; the descriptor is owned at once.
        unsafe {
            let fd = check(libc::inotify_init1(libc::IN_NONBLOCK | libc::IN_CLOEXEC))?;
            let fd = OwnedFd::from_raw_fd(fd);
            check(libc::inotify_add_watch(
                fd.as_raw_fd(),
                path.as_ptr(),
                libc::IN_OPEN,
            ))?;
            self.opens = Some(fd);
        }
        Ok(())
    }

    /// The board behind the terminal was replaced (powered off and on
    /// again): its UART output starts afresh, and the pace from now. The
    /// terminal stays, as the USB cable does.
    pub fn board_replaced(&mut self) {
        self.sent = 0;
        self.start = None;
        if let Some(second) = &mut self.second {
            second.board_replaced();
        }
    }

    pub fn set_pace(&mut self, pace: Pace) {
        self.pace = pace;
    }

    /// Whether a client opened the terminal since the last call.
    fn opened(&mut self) -> io::Result<bool> {
        let Some(fd) = &self.opens else {
            return Ok(false);
        };
        let mut buf = [0u8; 1024];
        let mut any = false;
        loop {
            // SAFETY: reads into a buffer of its length.
            let n = unsafe { libc::read(fd.as_raw_fd(), buf.as_mut_ptr().cast(), buf.len()) };
            match n {
                n if n > 0 => {
                    // Events are only ever IN_OPEN (the one watch, the one
                    // mask); each is at least a header long.
                    any = true;
                }
                0 => return Ok(any),
                _ => {
                    let e = io::Error::last_os_error();
                    return match e.kind() {
                        io::ErrorKind::WouldBlock => Ok(any),
                        _ => Err(e),
                    };
                }
            }
        }
    }

    /// Runs `sim` for `span` of simulated time, in step with the wall
    /// clock: what the client wrote goes to the UART first, what the UART
    /// sent goes to the client after. Returns how the last run ended.
    pub fn serve(&mut self, sim: &mut Sim, span: Duration) -> io::Result<Outcome> {
        if self.opened()? {
            // A closed USB port keeps nothing: what the board said while
            // no one listened is gone (here it waited in the terminal).
            // SAFETY: a descriptor this Pty owns.
            unsafe { libc::tcflush(self._slave.as_raw_fd(), libc::TCIFLUSH) };
            sim.reset_external();
        }
        self.start.get_or_insert((Instant::now(), sim.time_s()));
        if self.pace == Pace::RealTime {
            self.take_input(sim)?;
            let outcome = sim.run_for(span);
            self.give_output(sim)?;
            if let Some(second) = &mut self.second {
                second.take_input(sim)?;
                second.give_output(sim)?;
            }
            self.keep_pace(sim, None);
            return Ok(outcome);
        }
        // Busy link: in 1 ms steps while idle, so the host's next bytes
        // wait at most that long in simulated time.
        let end = sim.cycles() + cycles_in(span);
        let mut outcome = Outcome::Running;
        while sim.cycles() < end && !outcome.is_fatal() {
            let second_in = match &mut self.second {
                Some(second) => second.take_input(sim)? + second.give_output(sim)?,
                None => 0,
            };
            let busy = self.take_input(sim)? > 0 || sim.uart_pending() > 0 || second_in > 0;
            let step = match busy {
                true => end - sim.cycles(),
                false => (end - sim.cycles()).min(IDLE_STEP),
            };
            outcome = sim.run_cycles(step);
            let sent = self.give_output(sim)?;
            if busy || sent > 0 || sim.uart_pending() > 0 {
                // The wall clock's reference moves to now: the idle time
                // after is paced afresh.
                self.start = Some((Instant::now(), sim.time_s()));
            } else {
                self.keep_pace(sim, Some(&self.master));
            }
        }
        Ok(outcome)
    }

    /// What the client wrote, queued for the UART: how many bytes. The
    /// line honours XON/XOFF while the client's terminal has `IXON` on.
    fn take_input(&mut self, sim: &mut Sim) -> io::Result<usize> {
        let uart1 = self.uart1;
        // SAFETY: a termios filled by the call, on a descriptor this Pty owns.
        let ixon = unsafe {
            let mut tio: libc::termios = std::mem::zeroed();
            libc::tcgetattr(self._slave.as_raw_fd(), &mut tio) == 0 && tio.c_iflag & libc::IXON != 0
        };
        if !uart1 {
            sim.set_uart_xonxoff(ixon);
        }
        let mut buf = [0u8; 256];
        let mut got = 0;
        loop {
            match self.master.read(&mut buf) {
                Ok(0) => return Ok(got),
                Ok(n) => {
                    match uart1 {
                        false => sim.uart_send(&buf[..n]),
                        true => sim.uart1_send(&buf[..n]),
                    }
                    self.received.extend_from_slice(&buf[..n]);
                    got += n;
                }
                Err(e) if e.kind() == io::ErrorKind::WouldBlock => return Ok(got),
                // No client has the terminal open (Linux reports EIO).
                Err(e) if e.raw_os_error() == Some(libc::EIO) => return Ok(got),
                Err(e) => return Err(e),
            }
        }
    }

    /// What the UART sent, to the client: how many bytes.
    fn give_output(&mut self, sim: &Sim) -> io::Result<usize> {
        let out = match self.uart1 {
            false => &sim.uart_bytes()[self.sent..],
            true => &sim.uart1_bytes()[self.sent..],
        };
        let n = match self.master.write(out) {
            Ok(n) => n,
            Err(e) if e.kind() == io::ErrorKind::WouldBlock => 0,
            Err(e) if e.raw_os_error() == Some(libc::EIO) => out.len(),
            Err(e) => return Err(e),
        };
        self.sent += n;
        Ok(n)
    }

    /// Never ahead of the wall clock: waits until it catches up, or (with
    /// `wake`) until the client writes.
    fn keep_pace(&self, sim: &Sim, wake: Option<&File>) {
        let Some((wall, sim_start)) = self.start else {
            return;
        };
        let ahead = (sim.time_s() - sim_start) - wall.elapsed().as_secs_f64();
        if ahead <= 0.0 {
            return;
        }
        match wake {
            None => std::thread::sleep(Duration::from_secs_f64(ahead)),
            Some(file) => {
                let mut fd = libc::pollfd {
                    fd: file.as_raw_fd(),
                    events: libc::POLLIN,
                    revents: 0,
                };
                let ms = (ahead * 1000.0).ceil() as libc::c_int;
                // SAFETY: one valid pollfd for the call's length.
                unsafe { libc::poll(&mut fd, 1, ms) };
            }
        }
    }
}

/// Simulated time run at once while the line is idle (1 ms).
const IDLE_STEP: u64 = 16_000;

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
