//! The person at the machine, simulated: reads the string-art job's log
//! lines as they arrive, follows its state and progress, and presses the
//! green button whenever a prompt asks for it (`taut-sim --auto-confirm`,
//! the demo and the HIL job tests).

use crate::Sim;
use std::time::Duration;
use taut_logic::pinmap::Button;
use taut_logic::stringart::job::{Prompt, PROMPT_MARK};

/// How long a confirming press is held (well below a long press).
pub const PRESS: Duration = Duration::from_millis(150);

/// Something the operator read in the log.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Seen {
    /// `state: <name>`.
    State(String),
    /// A prompt line, without its mark.
    Prompt(String),
    /// `drill 3/24` or `wind 1234/3000 left 12s`: phase, done, total.
    Progress(String, u32, u32),
    /// An error line (`[MSG:E …]`).
    Error(String),
}

#[derive(Default)]
pub struct Operator {
    /// Presses green at prompts that ask for it.
    pub confirm: bool,
    /// UART bytes already read.
    read: usize,
    release_at: Option<f64>,
    /// Presses made so far.
    pub presses: u32,
    pub state: Option<String>,
    /// The job reached its end (`done: press green`).
    pub finished: bool,
}

/// The message text of a log line `[MSG:I 123 module: text]`.
pub fn message(line: &str) -> Option<&str> {
    let rest = line.strip_prefix("[MSG:")?.strip_suffix(']')?;
    let (_, text) = rest.split_once(": ")?;
    Some(text)
}

impl Operator {
    pub fn confirming() -> Operator {
        Operator {
            confirm: true,
            ..Operator::default()
        }
    }

    /// Reads the complete lines that arrived since the last call and acts
    /// on them; returns what was seen.
    pub fn step(&mut self, sim: &mut Sim) -> Vec<Seen> {
        if let Some(at) = self.release_at {
            if sim.time_s() >= at {
                sim.release(Button::Confirm.pin());
                self.release_at = None;
            }
        }
        let bytes = sim.uart_bytes();
        let Some(end) = bytes[self.read..].iter().rposition(|&b| b == b'\n') else {
            return Vec::new();
        };
        let text = String::from_utf8_lossy(&bytes[self.read..self.read + end]).into_owned();
        self.read += end + 1;
        let mut seen = Vec::new();
        for line in text.lines() {
            let Some(msg) = message(line) else { continue };
            if line.starts_with("[MSG:E") {
                seen.push(Seen::Error(msg.to_string()));
            } else if let Some(state) = msg.strip_prefix("state: ") {
                self.state = Some(state.to_string());
                seen.push(Seen::State(state.to_string()));
            } else if let Some(prompt) = msg.strip_prefix(PROMPT_MARK) {
                self.prompt(sim, msg);
                seen.push(Seen::Prompt(prompt.to_string()));
            } else if let Some(p) = progress(msg) {
                seen.push(p);
            }
        }
        seen
    }

    fn prompt(&mut self, sim: &mut Sim, line: &str) {
        if line == Prompt::Finished.as_str() {
            self.finished = true;
        } else if self.confirm && line.contains("press green") {
            sim.press(Button::Confirm.pin());
            self.release_at = Some(sim.time_s() + PRESS.as_secs_f64());
            self.presses += 1;
        }
    }
}

/// `drill 3/24 …` / `wind 10/30 …`.
fn progress(msg: &str) -> Option<Seen> {
    let (phase, rest) = msg.split_once(' ')?;
    if phase != "drill" && phase != "wind" {
        return None;
    }
    let counts = rest.split(' ').next()?;
    let (done, total) = counts.split_once('/')?;
    Some(Seen::Progress(
        phase.to_string(),
        done.parse().ok()?,
        total.parse().ok()?,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_lines_are_read_as_the_firmware_writes_them() {
        assert_eq!(
            message("[MSG:I 12 job: state: reading]"),
            Some("state: reading")
        );
        assert_eq!(message("[MSG:Caution: Unlocked]"), Some("Unlocked"));
        assert_eq!(message("ok"), None);
        assert_eq!(
            progress("wind 1234/3000 left 12s"),
            Some(Seen::Progress("wind".into(), 1234, 3000))
        );
        assert_eq!(
            progress("drill 3/24"),
            Some(Seen::Progress("drill".into(), 3, 24))
        );
        assert_eq!(progress("files ok: shape 6"), None);
    }
}
