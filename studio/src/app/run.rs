//! A G-code run: `taut send`'s character-counting stream
//! ([`crate::send::stream`]) fed by the hub with the machine's replies,
//! with the line counts, the planner's ETA and the states the page shows.
//! Nothing is ever sent again by itself: a run that was stopped, lost its
//! link or met an alarm is over, with its last acknowledged line.

use crate::send::stream::{Answer, Stream};
use crate::send::Eta;
use serde_json::{json, Value};
use std::time::Instant;
use taut_logic::config::MachineConfig;

#[derive(Clone, Debug, PartialEq)]
pub enum State {
    Running,
    Paused,
    Done,
    Interrupted(String),
}

pub struct Run {
    pub name: String,
    stream: Stream,
    eta: Eta,
    pub state: State,
    started: Instant,
    /// Every line answered: waiting for the machine to stand.
    finishing: Option<Instant>,
    /// Machine seconds left at the last answer.
    left_s: f64,
    /// The file's line number of the last line answered.
    last_acked: Option<usize>,
    /// Refused lines: the file's line number, the line, the reply.
    pub errors: Vec<(usize, String, String)>,
    /// A status report of motion seen since everything was answered.
    moved: bool,
}

impl Run {
    /// A run of `text`; its ETA from `config` (the machine's figures).
    pub fn new(name: &str, text: &[u8], config: &MachineConfig) -> Result<Run, String> {
        let stream = Stream::new(text)?;
        if stream.lines().is_empty() {
            return Err("the file has no G-code lines".into());
        }
        let eta = Eta::of(stream.lines(), config);
        Ok(Run {
            name: name.to_string(),
            left_s: eta.total,
            stream,
            eta,
            state: State::Running,
            started: Instant::now(),
            finishing: None,
            last_acked: None,
            errors: Vec::new(),
            moved: false,
        })
    }

    /// Still sending or held: the machine's answers are the run's.
    pub fn active(&self) -> bool {
        matches!(self.state, State::Running | State::Paused)
    }

    /// The lines that fit now, to be written in order.
    pub fn fill(&mut self, out: &mut Vec<Vec<u8>>) -> Result<(), String> {
        self.stream.fill(|line| {
            out.push(line.to_vec());
            Ok::<(), String>(())
        })
    }

    /// A reply line; notes for the console (refused lines, an alarm).
    pub fn on_reply(&mut self, line: &str) -> Vec<String> {
        if line.starts_with("Grbl ") {
            self.interrupt("the machine reset");
            return Vec::new();
        }
        match self.stream.reply(line) {
            Ok(Answer::Line { index, error }) => {
                let (number, text) = self.stream.lines()[index].clone();
                self.last_acked = Some(number);
                self.left_s = self.eta.total - self.eta.after[index];
                if self.stream.done() {
                    self.finishing = Some(Instant::now());
                }
                match error {
                    Some(e) => {
                        let note = format!("{}: line {number}: {text}: {e}", self.name);
                        self.errors.push((number, text, e));
                        vec![note]
                    }
                    None => Vec::new(),
                }
            }
            Ok(Answer::Alarm(alarm)) => {
                self.interrupt(&alarm);
                Vec::new()
            }
            Ok(Answer::Other) => Vec::new(),
            Err(e) => {
                self.interrupt(&e);
                Vec::new()
            }
        }
    }

    /// A status report's state; whether the run's state changed.
    pub fn on_status(&mut self, state: &str) -> bool {
        match (&self.state, self.finishing) {
            (State::Running, Some(_)) if state == "Idle" && self.moved_or_late() => {
                self.state = State::Done;
                self.left_s = 0.0;
                true
            }
            (State::Running, Some(_)) => {
                self.moved |= state != "Idle";
                false
            }
            _ => false,
        }
    }

    /// Motion was seen after the last answer, or a second has gone by (a
    /// file of no motion stands at once).
    fn moved_or_late(&self) -> bool {
        self.moved
            || self
                .finishing
                .is_some_and(|t| t.elapsed().as_secs_f64() > 1.0)
    }

    /// Paused (`!` sent) or running again (`~`).
    pub fn hold(&mut self, paused: bool) -> Result<(), String> {
        match (&self.state, paused) {
            (State::Running, true) => self.state = State::Paused,
            (State::Paused, false) => self.state = State::Running,
            (_, true) => return Err(format!("the run is {}, not running", self.word())),
            (_, false) => return Err(format!("the run is {}, not paused", self.word())),
        }
        Ok(())
    }

    /// Over, with why; the last acknowledged line is kept.
    pub fn interrupt(&mut self, why: &str) {
        if self.active() {
            let at = match self.last_acked {
                Some(n) => format!("last acknowledged line: {n}"),
                None => "no line acknowledged".to_string(),
            };
            self.state = State::Interrupted(format!("{why} ({at})"));
        }
    }

    fn word(&self) -> &'static str {
        match self.state {
            State::Running => "running",
            State::Paused => "paused",
            State::Done => "done",
            State::Interrupted(_) => "interrupted",
        }
    }

    /// `GET /api/run`.
    pub fn report(&self) -> Value {
        let of = self.stream.lines().len();
        let done_s = self.eta.total - self.left_s;
        let left_s = match (self.finishing, &self.state) {
            // The planner's last blocks are timed only as a whole: the
            // clock runs on through them.
            (Some(t), State::Running) => (self.left_s - t.elapsed().as_secs_f64()).max(0.0),
            _ => self.left_s,
        };
        json!({
            "name": self.name,
            "state": self.word(),
            "reason": match &self.state { State::Interrupted(r) => Some(r.clone()), _ => None },
            "line": self.stream.answered(),
            "of": of,
            "sent": self.stream.sent(),
            "last_acknowledged": self.last_acked,
            "percent": match self.state {
                State::Done => 100.0,
                _ if self.eta.total > 0.0 => (100.0 * done_s / self.eta.total).clamp(0.0, 100.0),
                _ => 100.0 * self.stream.answered() as f64 / of.max(1) as f64,
            },
            "eta_s": left_s,
            "estimate_s": self.eta.total,
            "elapsed_s": self.started.elapsed().as_secs_f64(),
            "errors": self.errors.iter().map(|(n, l, e)| json!({"line": n, "text": l, "reply": e})).collect::<Vec<_>>(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use taut_logic::machine::Machine;

    #[test]
    fn a_run_counts_answers_and_ends_when_the_machine_stands() {
        let cfg = MachineConfig::defaults(Machine::Flatbed);
        let mut run = Run::new("t", b"G21\nG1 X10 F600\n; c\nG1 X20\n", &cfg).unwrap();
        let mut out = Vec::new();
        run.fill(&mut out).unwrap();
        assert_eq!(
            out,
            [
                b"G21\n".to_vec(),
                b"G1X10F600\n".to_vec(),
                b"G1X20\n".to_vec()
            ]
        );
        assert!(run.on_reply("ok").is_empty());
        let notes = run.on_reply("[MSG:Travel exceeded (col 3)]");
        assert!(notes.is_empty());
        let notes = run.on_reply("error:15");
        assert_eq!(
            notes,
            ["t: line 2: G1X10F600: error:15 Travel exceeded (col 3)"]
        );
        assert_eq!(run.report()["line"], 2);
        run.hold(true).unwrap();
        assert!(run.hold(true).is_err());
        run.hold(false).unwrap();
        run.on_reply("ok");
        assert_eq!(run.report()["last_acknowledged"], 4);
        assert!(!run.on_status("Run"));
        assert!(run.on_status("Idle"));
        assert_eq!(run.report()["state"], "done");
        assert_eq!(run.report()["percent"], 100.0);
    }

    #[test]
    fn a_lost_link_or_an_alarm_interrupts_at_the_last_acknowledged_line() {
        let cfg = MachineConfig::defaults(Machine::Flatbed);
        let mut run = Run::new("t", b"G21\nG1 X10 F600\n", &cfg).unwrap();
        run.fill(&mut Vec::new()).unwrap();
        run.on_reply("ok");
        run.interrupt("connection lost");
        assert_eq!(run.report()["state"], "interrupted");
        assert_eq!(
            run.report()["reason"],
            "connection lost (last acknowledged line: 1)"
        );
        let mut run = Run::new("t", b"G21\n", &cfg).unwrap();
        run.on_reply("ALARM:3");
        assert_eq!(run.report()["reason"], "ALARM:3 (no line acknowledged)");
        assert!(Run::new("t", b"; nothing\n", &cfg).is_err());
    }
}
