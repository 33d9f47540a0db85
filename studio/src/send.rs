//! `taut send FILE [--port PATH] [--machine NAME]`: stream a G-code file
//! to the machine the way Grbl's own senders do, counting characters: as
//! many lines in flight as fit the firmware's 128-byte receive buffer, one
//! freed per `ok` or `error:N`. A bar shows the file's progress in machine
//! time, with the ETA the firmware's own planner works out for it on the
//! host (`taut_logic::interp::estimate`, with the figures the machine
//! lists in `$$`). Keys while it streams: `!` or
//! space holds, `~` or space again resumes, `q` or Ctrl-C stops the machine
//! (Ctrl-X) and quits. Every `error:N` is shown with its line and the
//! message the firmware put before it (`[MSG:…]`); at the end, a summary
//! once the machine stands; the exit status is non-zero after any error,
//! alarm or stop.
//!
//! The port: a Mega on USB (`/dev/ttyACM0`, the default; it resets when the
//! port opens, which is waited out: its greeting comes within a few
//! seconds) or the simulator's pseudo-terminal (`cargo xtask sim --pty
//! PATH`: it greeted before the port opened, so a Ctrl-X asks again).

mod port;
pub mod stream;

use crate::args::AnyMachine;
use indicatif::{ProgressBar, ProgressStyle};
use port::Port;
use std::io::Read;
use std::path::PathBuf;
use std::sync::mpsc::{self, Receiver};
use std::time::{Duration, Instant};
use stream::{Answer, Stream};
use taut_logic::config::MachineConfig;
use taut_logic::interp::estimate::GcodeTime;
use taut_logic::machine::Machine;
use taut_logic::settings;

/// Streams a G-code file to the machine, Grbl's way, with progress and ETA
///
/// Lines go by character counting (Grbl's 128-byte buffer), with a bar and
/// the firmware planner's ETA. Keys: `!` or space hold, `~` or space resume,
/// `q` or Ctrl-C stop (Ctrl-X) and quit. Exit status 1 after any error,
/// alarm or stop.
#[derive(clap::Args, Debug)]
#[command(after_help = "\
Examples:
  taut send drawing.gcode                       (a Mega on /dev/ttyACM0)
  cargo xtask sim --pty /tmp/taut-tty --machine flatbed
  taut send drawing.gcode --port /tmp/taut-tty")]
pub struct Cli {
    /// The G-code file
    pub file: PathBuf,
    /// The serial port: the Mega, or the simulator's terminal
    #[arg(long, default_value = "/dev/ttyACM0")]
    pub port: String,
    /// The machine whose default figures the ETA is worked out with [default: what the machine lists in $$]
    #[arg(long, value_enum)]
    pub machine: Option<AnyMachine>,
}

/// Whether a line is a program pause (`M0`, `M00`, `M1`), outside its
/// comments.
fn is_pause(line: &str) -> bool {
    let code: String = line
        .split(['(', ';'])
        .next()
        .unwrap_or("")
        .chars()
        .filter(|c| !c.is_whitespace())
        .collect::<String>()
        .to_ascii_uppercase();
    let mut rest = code.as_str();
    while let Some(at) = rest.find('M') {
        let digits: String = rest[at + 1..]
            .chars()
            .take_while(|c| c.is_ascii_digit())
            .collect();
        if matches!(digits.trim_start_matches('0'), "" | "1") && !digits.is_empty() {
            return true;
        }
        rest = &rest[at + 1..];
    }
    false
}

pub fn run(cli: Cli) -> Result<(), String> {
    let (file, port) = (cli.file.display().to_string(), cli.port);
    let chosen = cli.machine.map(Machine::from);
    let machine = chosen.map(|m| m.name().to_string());
    let text = std::fs::read(&file).map_err(|e| format!("{file}: {e}"))?;
    let stream = Stream::new(&text)?;
    let mut port = Port::open(&port)?;
    let mut replies = port.replies()?;
    greet(&mut port, &mut replies)?;
    // In alarm every line would be refused, one error each: say so once.
    if state(&mut port, &mut replies)?.as_deref() == Some("Alarm") {
        return Err("the machine is in alarm: unlock it ($X) or home it ($H) first".into());
    }
    // The ETA plans for the figures the machine runs with, read from its
    // `$$`, unless told which machine's defaults to take.
    let (name, config) = match (chosen, machine) {
        (Some(m), Some(name)) => (name, MachineConfig::defaults(m)),
        _ => listed_config(&mut port, &mut replies)
            .unwrap_or(("string_art".into(), MachineConfig::STRING_ART)),
    };
    let eta = Eta::of(stream.lines(), &config);
    let count = stream.lines().len();
    eprintln!(
        "taut send: {count} lines to the {name}, {} of machine time by its planner",
        clock(eta.total)
    );
    let keys = keys();
    let started = Instant::now();
    let outcome = send(&mut port, &mut replies, stream, &eta, &keys);
    drop(keys);
    let Outcome {
        answered,
        errors,
        alarm,
    } = outcome?;
    println!(
        "taut send: {answered} of {count} lines answered, {errors} error(s), {} (the planner said {})",
        clock(started.elapsed().as_secs_f64()),
        clock(eta.total)
    );
    match (errors, alarm) {
        (0, None) => Ok(()),
        (n, None) => Err(format!("{n} line(s) answered with an error")),
        (_, Some(a)) => Err(format!("the machine stopped: {a}")),
    }
}

/// `m:ss.s`, or `h:mm:ss` from an hour.
fn clock(s: f64) -> String {
    let s = s.max(0.0);
    match s < 3600.0 {
        true => format!("{}:{:04.1}", (s / 60.0) as u64, s % 60.0),
        false => {
            let t = s as u64;
            format!("{}:{:02}:{:02}", t / 3600, t / 60 % 60, t % 60)
        }
    }
}

/// The machine's configuration from its `$$`: the defaults of the machine
/// `$machine` names under the named settings listed after it. `None` from
/// a Grbl that is not taut (no `$machine`) or no listing.
fn listed_config(
    port: &mut Port,
    replies: &mut Receiver<String>,
) -> Option<(String, MachineConfig)> {
    port.write(b"$$\n").ok()?;
    let until = Instant::now() + Duration::from_secs(3);
    let mut listing = Vec::new();
    loop {
        let line = replies
            .recv_timeout(until.checked_duration_since(Instant::now())?)
            .ok()?;
        match line.as_str() {
            "ok" => break,
            l if l.starts_with("error:") => return None,
            l => listing.push(l.to_string()),
        }
    }
    config_of(&listing)
}

pub fn config_of(listing: &[String]) -> Option<(String, MachineConfig)> {
    // Grbl's numbered settings (`$110=…`) stand for named ones: skipped.
    let named: Vec<(&str, &str)> = listing
        .iter()
        .filter_map(|l| l.strip_prefix('$')?.split_once('='))
        .filter(|(k, _)| !k.starts_with(|c: char| c.is_ascii_digit()))
        .collect();
    let (_, name) = named
        .iter()
        .find(|(k, _)| k.eq_ignore_ascii_case("machine"))?;
    let mut cfg = MachineConfig::defaults(Machine::parse(name.trim().as_bytes())?);
    // Each setting must leave the whole valid (`settings::set` checks):
    // one the first pass refuses for a neighbour not yet set, the second
    // takes.
    for _ in 0..2 {
        for (k, v) in named.iter().filter(|(k, _)| *k != "machine") {
            let _ = settings::set(&mut cfg, k, v);
        }
    }
    Some((name.trim().to_string(), cfg))
}

/// Machine time at the end of each line, from the firmware's planner.
/// Counted when the planner hands a block on, it lags the line by the
/// planner's depth, as the machine lags the `ok` (the firmware answers a
/// line when it is queued): the two lags cancel on the bar.
pub struct Eta {
    pub after: Vec<f64>,
    pub total: f64,
}

impl Eta {
    pub fn of(lines: &[(usize, String)], config: &MachineConfig) -> Eta {
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
                Ok(line) if line.contains("Grbl ") => return true,
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

/// The machine's state from a status report (`<Idle|…>` → `Idle`).
fn state(port: &mut Port, replies: &mut Receiver<String>) -> Result<Option<String>, String> {
    port.write(b"?")?;
    let until = Instant::now() + Duration::from_secs(1);
    while let Some(left) = until.checked_duration_since(Instant::now()) {
        match replies.recv_timeout(left) {
            Ok(r) if r.starts_with('<') => {
                let word = r[1..].split(['|', ':', '>']).next().unwrap_or_default();
                return Ok(Some(word.to_string()));
            }
            Ok(_) => {}
            Err(_) => break,
        }
    }
    Ok(None)
}

#[derive(Default)]
struct Outcome {
    answered: usize,
    errors: usize,
    alarm: Option<String>,
}

/// The bar: machine milliseconds done of the planner's total, the time
/// left by the planner, and whether the machine is held.
struct Progress {
    bar: ProgressBar,
    left: f64,
    held: bool,
}

impl Progress {
    fn new(total: f64) -> Result<Progress, String> {
        let bar = ProgressBar::new((total * 1000.0) as u64);
        bar.set_style(
            ProgressStyle::with_template(
                "{spinner} {elapsed_precise} [{wide_bar}] {percent:>3}% {msg}",
            )
            .map_err(|e| e.to_string())?
            .progress_chars("=> "),
        );
        let p = Progress {
            bar,
            left: total,
            held: false,
        };
        p.show();
        Ok(p)
    }

    fn show(&self) {
        let held = match self.held {
            true => "  HELD (~ resumes)",
            false => "",
        };
        self.bar
            .set_message(format!("ETA {}{held}", clock(self.left)));
    }
}

/// The bar left as it stands on every way out, the cursor under it
/// (indicatif leaves it at the line's end, where the next message would
/// run on).
impl Drop for Progress {
    fn drop(&mut self) {
        self.bar.abandon();
        if !self.bar.is_hidden() {
            eprintln!();
        }
    }
}

fn send(
    port: &mut Port,
    replies: &mut Receiver<String>,
    mut stream: Stream,
    eta: &Eta,
    keys: &Keys,
) -> Result<Outcome, String> {
    let mut p = Progress::new(eta.total)?;
    let mut o = Outcome::default();
    while !stream.done() {
        stream.fill(|line| port.write(line))?;
        keys.act(port, &mut p)?;
        let reply = match replies.recv_timeout(Duration::from_millis(50)) {
            Ok(reply) => reply,
            Err(mpsc::RecvTimeoutError::Timeout) => continue,
            Err(mpsc::RecvTimeoutError::Disconnected) => return Err("the port closed".into()),
        };
        match stream.reply(&reply)? {
            Answer::Line { index, error } => {
                let (number, text) = &stream.lines()[index];
                match error {
                    Some(error) => p
                        .bar
                        .suspend(|| eprintln!("line {number}: {text}: {error}")),
                    // A program pause (M0, as a pen change): the machine
                    // holds there; the line's comment says what to do.
                    None if is_pause(text) => p.bar.suspend(|| {
                        eprintln!("line {number}: paused: {text} — resume with ~ or space")
                    }),
                    None => {}
                }
                p.bar.set_position((eta.after[index] * 1000.0) as u64);
                p.left = eta.total - eta.after[index];
                p.show();
            }
            Answer::Alarm(alarm) => {
                o.alarm = Some(alarm);
                break;
            }
            Answer::Other => {}
        }
        (o.answered, o.errors) = (stream.answered(), stream.errors());
    }
    (o.answered, o.errors) = (stream.answered(), stream.errors());
    if o.alarm.is_some() {
        return Ok(o);
    }
    // Every line queued: wait until the machine stands.
    o.alarm = wait_idle(port, replies, keys, &mut p)?;
    if o.alarm.is_none() {
        p.left = 0.0;
        p.bar.set_position(p.bar.length().unwrap_or(0));
        p.show();
    }
    Ok(o)
}

/// Polls `?` every 200 ms until the status report says `Idle` (keys still
/// act: a hold near the end must be resumable, a stop possible); an alarm
/// on the way.
fn wait_idle(
    port: &mut Port,
    replies: &mut Receiver<String>,
    keys: &Keys,
    p: &mut Progress,
) -> Result<Option<String>, String> {
    // The planner's last blocks are timed only as a whole (after the last
    // `ok`): the bar runs on through them by the clock.
    let (from, left) = (Instant::now(), p.left);
    loop {
        keys.act(port, p)?;
        if !p.held {
            p.left = (left - from.elapsed().as_secs_f64()).max(0.0);
            let len = p.bar.length().unwrap_or(0);
            p.bar
                .set_position(len - (p.left * 1000.0).min(len as f64) as u64);
            p.show();
        }
        port.write(b"?")?;
        let until = Instant::now() + Duration::from_millis(200);
        while let Some(left) = until.checked_duration_since(Instant::now()) {
            match replies.recv_timeout(left) {
                Ok(r) if r.starts_with("<Idle") => return Ok(None),
                Ok(r) if r.starts_with("ALARM:") || r.starts_with("<Alarm") => return Ok(Some(r)),
                Ok(_) => {}
                Err(mpsc::RecvTimeoutError::Timeout) => break,
                Err(mpsc::RecvTimeoutError::Disconnected) => return Err("the port closed".into()),
            }
        }
    }
}

/// The keyboard, one key at a time when it is a terminal (its mode put
/// back when this drops); SIGINT caught when it is not.
struct Keys {
    pressed: Receiver<u8>,
    _raw: Option<port::TermMode>,
}

impl Keys {
    /// Sends what the keys pressed since the last call ask for; an error
    /// after a stop (the machine reset with Ctrl-X).
    fn act(&self, port: &mut Port, p: &mut Progress) -> Result<(), String> {
        let interrupt = port::interrupted().then_some(0x03);
        for key in self.pressed.try_iter().chain(interrupt) {
            match key {
                b'!' | b' ' if !p.held => {
                    port.write(b"!")?;
                    p.held = true;
                }
                b'~' | b' ' if p.held => {
                    port.write(b"~")?;
                    p.held = false;
                }
                b'q' | b'Q' | 0x03 => {
                    port.write(&[0x18])?;
                    return Err("stopped (Ctrl-X sent: the machine reset)".into());
                }
                _ => continue,
            }
            p.show();
        }
        Ok(())
    }
}

fn keys() -> Keys {
    let raw = port::TermMode::raw_stdin();
    let (tx, pressed) = mpsc::channel();
    match raw {
        Some(_) => {
            std::thread::spawn(move || {
                let mut byte = [0u8];
                while std::io::stdin().read_exact(&mut byte).is_ok() && tx.send(byte[0]).is_ok() {}
            });
        }
        None => port::catch_sigint(),
    }
    Keys { pressed, _raw: raw }
}

#[cfg(test)]
mod tests;
