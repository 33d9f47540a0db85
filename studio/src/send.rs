//! `taut send FILE [--port PATH] [--machine NAME]`: stream a G-code file
//! to the machine the way Grbl's own senders do, counting characters: as
//! many lines in flight as fit the firmware's 128-byte receive buffer, one
//! freed per `ok` or `error:N`. A bar shows the file's progress in machine
//! time, with the ETA the firmware's own planner works out for it on the
//! host (`taut_logic::interp::estimate`). Keys while it streams: `!` or
//! space holds, `~` or space again resumes, `q` or Ctrl-C stops the machine
//! (Ctrl-X) and quits. Every `error:N` is shown with its line and the
//! message the firmware put before it (`[MSG:…]`); the exit status is
//! non-zero after any error or alarm.
//!
//! The port: a Mega on USB (`/dev/ttyACM0`, the default; it resets when the
//! port opens, which is waited out: its greeting comes within a few
//! seconds) or the simulator's pseudo-terminal (`cargo xtask sim --pty
//! PATH`: it greeted before the port opened, so a Ctrl-X asks again).

mod port;

use crate::args::Args;
use indicatif::{ProgressBar, ProgressStyle};
use port::Port;
use std::collections::VecDeque;
use std::io::Read;
use std::sync::mpsc::{self, Receiver};
use std::time::{Duration, Instant};
use taut_logic::config::MachineConfig;
use taut_logic::interp::estimate::GcodeTime;
use taut_logic::machine::Machine;

pub const USAGE: &str = "\
taut send FILE [--port PATH] [--machine NAME]
    stream a G-code file to the machine counting characters (Grbl's 128-byte
    buffer), with progress and the firmware planner's ETA; keys: ! or space
    hold, ~ or space resume, q or Ctrl-C stop (Ctrl-X) and quit. PATH: the
    Mega (/dev/ttyACM0, default) or the simulator's terminal (cargo xtask sim
    --pty PATH). NAME: the machine the ETA is worked out for (default
    string_art; the file's own moves set the pace either way). Exit status 1
    after any error or alarm.";

/// Grbl 1.1's receive buffer; senders keep one byte of it free, as Grbl's
/// own stream.py and grbl-streamer do (bytes of lines sent and not yet
/// answered stay under it).
const RX_BUFFER: usize = 128;

/// Character counting: the lines sent and not yet answered, oldest first
/// (index into the file's lines, bytes with the newline). Grbl answers in
/// order, so each `ok` or `error:` frees the oldest.
#[derive(Default)]
struct Window {
    in_flight: VecDeque<(usize, usize)>,
    bytes: usize,
}

impl Window {
    /// `line` (without its newline) fits beside the bytes in flight.
    fn fits(&self, line: &str) -> bool {
        self.bytes + line.len() + 1 < RX_BUFFER
    }

    fn sent(&mut self, index: usize, line: &str) {
        self.in_flight.push_back((index, line.len() + 1));
        self.bytes += line.len() + 1;
    }

    /// A reply came: the index of the line it answers.
    fn answered(&mut self) -> Option<usize> {
        let (i, n) = self.in_flight.pop_front()?;
        self.bytes -= n;
        Some(i)
    }
}

pub fn run(mut args: Args) -> Result<(), String> {
    let file = args.positional("FILE")?;
    let port = args.value("port").unwrap_or_else(|| "/dev/ttyACM0".into());
    let machine = match args.value("machine") {
        Some(name) => Machine::parse(name.as_bytes()).ok_or(format!("no machine {name:?}"))?,
        None => Machine::StringArt,
    };
    args.finish()?;
    let text = std::fs::read(&file).map_err(|e| format!("{file}: {e}"))?;
    let lines = lines_of(&text);
    let eta = Eta::of(&lines, &MachineConfig::defaults(machine));
    let mut port = Port::open(&port)?;
    let mut replies = port.replies()?;
    greet(&mut port, &mut replies)?;
    let keys = keys();
    let outcome = stream(&mut port, &mut replies, &lines, &eta, &keys);
    keys.restore();
    let Outcome { errors, alarm } = outcome?;
    match (errors, alarm) {
        (0, None) => Ok(()),
        (n, None) => Err(format!("{n} line(s) answered with an error")),
        (_, Some(a)) => Err(format!("the machine stopped: {a}")),
    }
}

/// The file's lines as sent: comments and blanks kept out (they cost
/// buffer space and change nothing), each with its line number.
fn lines_of(text: &[u8]) -> Vec<(usize, String)> {
    String::from_utf8_lossy(text)
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.split(';').next().unwrap_or("").trim().to_string()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('%'))
        .collect()
}

/// Machine time at the end of each line, from the firmware's planner.
struct Eta {
    after: Vec<f64>,
    total: f64,
}

impl Eta {
    fn of(lines: &[(usize, String)], config: &MachineConfig) -> Eta {
        let Some(mut t) = GcodeTime::new(config) else {
            return Eta {
                after: vec![0.0; lines.len()],
                total: 0.0,
            };
        };
        let after = lines
            .iter()
            .map(|(_, l)| {
                t.push(l.as_bytes());
                t.push(b"\n");
                t.seconds()
            })
            .collect();
        Eta {
            after,
            total: t.finish(),
        }
    }
}

/// Waits for the greeting (`Grbl 1.1h …`); without one (the simulator
/// greeted before the port opened) asks for it with a soft reset. Then
/// whatever follows it is passed over until the port is quiet: replies to
/// lines sent before this sender came (a pseudo-terminal keeps them) must
/// not be counted as answers to the file's lines.
fn greet(port: &mut Port, replies: &mut Receiver<String>) -> Result<(), String> {
    let greeted = |replies: &mut Receiver<String>, wait: Duration| {
        let until = Instant::now() + wait;
        while let Some(left) = until.checked_duration_since(Instant::now()) {
            match replies.recv_timeout(left) {
                Ok(line) if line.starts_with("Grbl ") => return true,
                Ok(_) => {}
                Err(_) => return false,
            }
        }
        false
    };
    // A Mega resets as the port opens: its boot loader waits ~1.6 s.
    if !greeted(replies, Duration::from_millis(2500)) {
        port.write(&[0x18])?;
        if !greeted(replies, Duration::from_secs(3)) {
            return Err("no Grbl greeting on the port".into());
        }
    }
    while replies.recv_timeout(Duration::from_millis(300)).is_ok() {}
    Ok(())
}

struct Outcome {
    errors: usize,
    alarm: Option<String>,
}

fn stream(
    port: &mut Port,
    replies: &mut Receiver<String>,
    lines: &[(usize, String)],
    eta: &Eta,
    keys: &Keys,
) -> Result<Outcome, String> {
    let bar = ProgressBar::new((eta.total * 1000.0) as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} {elapsed_precise} [{bar:40}] {msg} ETA {eta_precise}",
        )
        .map_err(|e| e.to_string())?,
    );
    let mut window = Window::default();
    let (mut next, mut answered, mut errors) = (0, 0, 0);
    let mut held = false;
    // The firmware's words for an error come just before its `error:N`.
    let mut message = String::new();
    loop {
        // Fill the buffer.
        while let Some((_, line)) = lines.get(next).filter(|(_, l)| window.fits(l)) {
            port.write(format!("{line}\n").as_bytes())?;
            window.sent(next, line);
            next += 1;
        }
        if answered == lines.len() {
            break;
        }
        for key in keys.pressed() {
            match key {
                b'!' | b' ' if !held => {
                    port.write(b"!")?;
                    held = true;
                    bar.set_message("held (~ or space resumes)");
                }
                b'~' | b' ' if held => {
                    port.write(b"~")?;
                    held = false;
                    bar.set_message("");
                }
                b'q' | 0x03 => {
                    port.write(&[0x18])?;
                    bar.abandon();
                    return Err("stopped from the keyboard (Ctrl-X sent)".into());
                }
                _ => {}
            }
        }
        let Ok(reply) = replies.recv_timeout(Duration::from_millis(50)) else {
            continue;
        };
        if reply == "ok" || reply.starts_with("error:") {
            let i = window
                .answered()
                .ok_or(format!("a reply with no line sent: {reply}"))?;
            answered += 1;
            if reply != "ok" {
                errors += 1;
                let (number, text) = &lines[i];
                bar.suspend(|| eprintln!("line {number}: {text}: {reply} {message}"));
            }
            bar.set_position((eta.after[i] * 1000.0) as u64);
        } else if reply.starts_with("ALARM:") {
            bar.abandon();
            return Ok(Outcome {
                errors,
                alarm: Some(reply),
            });
        } else if let Some(m) = reply
            .strip_prefix("[MSG:")
            .and_then(|m| m.strip_suffix(']'))
        {
            message = m.to_string();
            continue;
        }
        message.clear();
    }
    // Every line queued: wait until the machine stands.
    let end = wait_idle(port, replies);
    bar.finish();
    end.map(|alarm| Outcome { errors, alarm })
}

/// Polls `?` until the status report says `Idle`; an alarm on the way.
fn wait_idle(port: &mut Port, replies: &mut Receiver<String>) -> Result<Option<String>, String> {
    loop {
        port.write(b"?")?;
        let until = Instant::now() + Duration::from_millis(200);
        while let Some(left) = until.checked_duration_since(Instant::now()) {
            match replies.recv_timeout(left) {
                Ok(r) if r.starts_with("<Idle") => return Ok(None),
                Ok(r) if r.starts_with("ALARM:") => return Ok(Some(r)),
                Ok(_) => {}
                Err(mpsc::RecvTimeoutError::Timeout) => break,
                Err(mpsc::RecvTimeoutError::Disconnected) => return Err("the port closed".into()),
            }
        }
    }
}

/// The keyboard, one key at a time when it is a terminal.
struct Keys {
    pressed: Receiver<u8>,
    saved: Option<port::TermMode>,
}

impl Keys {
    fn pressed(&self) -> Vec<u8> {
        self.pressed.try_iter().collect()
    }

    fn restore(self) {
        if let Some(mode) = self.saved {
            mode.restore();
        }
    }
}

fn keys() -> Keys {
    let saved = port::TermMode::raw_stdin();
    let (tx, pressed) = mpsc::channel();
    if saved.is_some() {
        std::thread::spawn(move || {
            let mut byte = [0u8];
            while std::io::stdin().read_exact(&mut byte).is_ok() && tx.send(byte[0]).is_ok() {}
        });
    }
    Keys { pressed, saved }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_and_blanks_stay_home_and_lines_keep_their_numbers() {
        let lines = lines_of(b"; a drawing\nG21\n\n G1 X1 ; out\n%\nM5\n");
        assert_eq!(
            lines,
            [
                (2, "G21".to_string()),
                (4, "G1 X1".into()),
                (6, "M5".into())
            ]
        );
    }

    #[test]
    fn the_window_holds_what_grbl_s_buffer_holds_and_frees_in_order() {
        let mut w = Window::default();
        let line = "G1 X10.000 Y20.000"; // 19 bytes with its newline
        let mut sent = 0;
        while w.fits(line) {
            w.sent(sent, line);
            sent += 1;
        }
        assert_eq!(sent, 128 / 19);
        assert!(w.bytes < RX_BUFFER && w.bytes + 19 >= RX_BUFFER);
        assert_eq!(w.answered(), Some(0));
        assert!(w.fits(line), "an ok frees a line's room");
        assert_eq!(w.answered(), Some(1));
        // The longest line fits an empty window only.
        let mut w = Window::default();
        let long = "X".repeat(126);
        assert!(w.fits(&long));
        w.sent(0, "G0");
        assert!(!w.fits(&long));
        assert_eq!(w.answered(), Some(0));
        assert_eq!(w.answered(), None, "no reply without a line");
    }

    #[test]
    fn the_eta_grows_line_by_line_to_the_total() {
        let lines = lines_of(b"G21 G90\nG1 X10 F600\nG4 P500\nG1 X20\n");
        let eta = Eta::of(&lines, &MachineConfig::defaults(Machine::Flatbed));
        assert!(
            eta.after.windows(2).all(|w| w[0] <= w[1]),
            "{:?}",
            eta.after
        );
        assert!(
            eta.total > 2.0 && eta.total >= eta.after[3],
            "{}",
            eta.total
        );
    }
}
