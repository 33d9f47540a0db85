//! The person at the machine, simulated: reads the string-art job's log
//! lines as they arrive, follows its state and progress, and presses the
//! green button whenever a prompt asks for it (`taut-sim --auto-confirm`,
//! the demo and the HIL job tests). After a power cut it takes the resume
//! offer (green) and zeroes again: the axes, unpowered, are put back at
//! the zero pose by hand — in the simulator they never left it, since each
//! run's trace starts there — and each white button is pressed twice.

use crate::Sim;
use std::collections::VecDeque;
use std::time::Duration;
use taut_logic::pinmap::Button;
use taut_logic::stringart::job::{Prompt, PROMPT_MARK};

/// How long a confirming press is held (well below a long press).
pub const PRESS: Duration = Duration::from_millis(150);

/// Between two scripted presses, s (debouncing takes 20 ms).
const GAP_S: f64 = 0.1;

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
    /// Button changes to make: when (simulated s), which pin, pressed.
    script: VecDeque<(f64, u8, bool)>,
    /// Presses of green made so far.
    pub presses: u32,
    /// Resume offers taken (green at `>>> resume …`).
    pub resumes: u32,
    pub state: Option<String>,
    /// The last progress line: phase, done, total.
    pub progress: Option<(String, u32, u32)>,
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

    /// Runs the string-art job, this operator at the buttons, through its
    /// drilling, the wait for nails and into the winding: the (awake, all)
    /// cycles at each of the three, the MCU's busy share between them.
    /// Panics past 1 000 s of simulated time or if the simulation stops.
    pub fn job_phases(&mut self, sim: &mut Sim) -> Vec<(u64, u64)> {
        let mut marks = Vec::new();
        for state in [
            "state: drilling",
            "state: waiting for nails",
            "state: winding",
        ] {
            let from = sim.uart_text().len();
            while !sim.uart_text()[from..].contains(state) {
                assert_eq!(
                    sim.run_for(Duration::from_millis(10)),
                    crate::Outcome::Running
                );
                self.step(sim);
                assert!(sim.time_s() < 1000.0, "{}", sim.uart_text());
            }
            marks.push(awake_and_all(sim));
        }
        marks
    }

    /// Reads the complete lines that arrived since the last call and acts
    /// on them; returns what was seen.
    pub fn step(&mut self, sim: &mut Sim) -> Vec<Seen> {
        while let Some(&(at, pin, pressed)) = self.script.front() {
            if sim.time_s() < at {
                break;
            }
            self.script.pop_front();
            match pressed {
                true => sim.press(pin),
                false => sim.release(pin),
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
                if let Seen::Progress(phase, done, total) = &p {
                    self.progress = Some((phase.clone(), *done, *total));
                }
                seen.push(p);
            }
        }
        seen
    }

    fn prompt(&mut self, sim: &mut Sim, line: &str) {
        if line == Prompt::Finished.as_str() {
            self.finished = true;
        } else if !self.confirm {
        } else if line == Prompt::ZeroToResume.as_str() {
            // Each axis: driver off (turned to the zero pose by hand),
            // then taken as zero; then green.
            for b in [Button::ZeroBase, Button::ZeroRadial, Button::ZeroDrill] {
                self.click(sim, b.pin());
                self.click(sim, b.pin());
            }
            self.green(sim);
        } else if line.starts_with(">>> resume ") {
            self.resumes += 1;
            self.green(sim);
        } else if line.contains("press green") {
            self.green(sim);
        }
    }

    fn green(&mut self, sim: &Sim) {
        self.click(sim, Button::Confirm.pin());
        self.presses += 1;
    }

    /// A short press after the scripted ones, a gap after it.
    fn click(&mut self, sim: &Sim, pin: u8) {
        let from = self.script.back().map_or(sim.time_s(), |s| s.0 + GAP_S);
        self.script.push_back((from, pin, true));
        self.script
            .push_back((from + PRESS.as_secs_f64(), pin, false));
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

/// The cycles the MCU was awake and all cycles, so far.
pub fn awake_and_all(sim: &Sim) -> (u64, u64) {
    (sim.cycles() - sim.asleep_cycles(), sim.cycles())
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
