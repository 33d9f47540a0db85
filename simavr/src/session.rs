//! One run of the simulated machine as `taut-sim` makes it, from power-on
//! (or from where the caller left it) to its ending: the job's end, the
//! time limit, a power cut, an alarm under a job, a fault, or a signal.
//!
//! Every deadline is a cycle count, so a power cut planned for cycle C
//! stops the MCU at the first instruction boundary at or after C (an
//! instruction is never split; asleep, the sleep ends at C), whatever C
//! is: no float seconds are compared. A cut on text (`Cut::On`) is planned
//! at the cycle the text's last byte left the UART plus the delay, and the
//! run lasts until it, past its limit and past the job's end.

use crate::operator::{Operator, Seen};
use crate::pty::Pty;
use crate::serial;
use crate::{Outcome, Sim};
use std::sync::atomic::{AtomicBool, Ordering};

/// Cycles of simulated time between two looks at the machine (10 ms).
const SLICE: u64 = 160_000;

/// When the power goes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Cut {
    /// At this cycle since power-on.
    At(u64),
    /// `delay` cycles after the firmware's serial output first holds `text`.
    On { text: String, delay: u64 },
}

/// What a run is asked to do.
#[derive(Clone, Debug, Default)]
pub struct Plan {
    /// The run ends at this cycle since power-on, unless a planned cut
    /// comes later (the run then lasts until the cut).
    pub limit: Option<u64>,
    pub cut: Option<Cut>,
    /// The operator presses green at each prompt, and the run ends when
    /// the job (the string-art job, a print from the card) is done.
    pub auto_confirm: bool,
    /// A file was streamed to the console before the run (`--send`): that
    /// was the job, done once the limit comes with no other job under way.
    pub file_sent: bool,
}

/// How a run ended, in a user's words ([`Ending::words`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Ending {
    /// The string-art job said it was done, or the card's print did.
    JobFinished,
    /// The time limit came; `job` says how far a job under way had got.
    Limit { job: Option<String> },
    /// The power was cut at this cycle, as asked.
    PowerCut { cycle: u64 },
    /// A cut was asked for and never came (its text never appeared).
    CutMissed { text: String },
    /// An alarm (`ALARM:n`) stopped the job under way.
    Alarm { line: String },
    /// The firmware crashed, hung or overflowed its stack.
    Fault(Outcome),
    /// SIGINT or SIGTERM.
    Stopped,
}

impl Ending {
    /// The summary's last words: how the run ended.
    pub fn words(&self) -> String {
        match self {
            Ending::JobFinished => "job finished".into(),
            Ending::Limit { job: None } => "time limit reached".into(),
            Ending::Limit { job: Some(at) } => format!("stopped by the time limit at {at}"),
            Ending::PowerCut { cycle } => format!(
                "power cut at cycle {cycle} ({:.6} s)",
                *cycle as f64 / crate::clock::FREQ_HZ as f64
            ),
            Ending::CutMissed { text } => {
                format!("no power cut: {text:?} never appeared on the serial port")
            }
            Ending::Alarm { line } => format!("alarm ({line})"),
            Ending::Fault(o) => format!("firmware fault: {o:?}"),
            Ending::Stopped => "stopped by a signal".into(),
        }
    }

    /// The process's exit status: 0 for the endings asked for (the job
    /// done, the cut made, the limit of a run with no job under way, a
    /// signal), 3 when the limit cut a job short, 4 for an alarm, 1 for a
    /// fault or a cut that did not happen.
    pub fn exit_code(&self) -> u8 {
        match self {
            Ending::JobFinished
            | Ending::PowerCut { .. }
            | Ending::Stopped
            | Ending::Limit { job: None } => 0,
            Ending::Limit { job: Some(_) } => 3,
            Ending::Alarm { .. } => 4,
            Ending::Fault(_) | Ending::CutMissed { .. } => 1,
        }
    }

    /// The string for a JSON report's `ended`.
    pub fn kind(&self) -> &'static str {
        match self {
            Ending::JobFinished => "job finished",
            Ending::Limit { job: None } => "time limit",
            Ending::Limit { job: Some(_) } => "stopped by the time limit",
            Ending::PowerCut { .. } => "power cut",
            Ending::CutMissed { .. } => "no power cut",
            Ending::Alarm { .. } => "alarm",
            Ending::Fault(_) => "fault",
            Ending::Stopped => "stopped",
        }
    }
}

/// A print from the card as its serial lines tell it (Marlin's words).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Print {
    /// `File opened: NAME Size: N`.
    pub opened: Option<String>,
    pub running: bool,
    pub done: bool,
}

/// A run under way: the machine, its operator and what was seen.
pub struct Session<'a> {
    pub sim: &'a mut Sim,
    pub operator: Operator,
    pub print: Print,
    /// The first alarm line seen, if any.
    pub alarm: Option<String>,
    /// UART bytes already read for the print's and the alarms' lines.
    read: usize,
    /// UART bytes searched for a cut's text.
    searched: usize,
}

impl<'a> Session<'a> {
    pub fn new(sim: &'a mut Sim, plan: &Plan) -> Session<'a> {
        let operator = match plan.auto_confirm {
            true => Operator::confirming(),
            false => Operator::default(),
        };
        Session {
            sim,
            operator,
            print: Print::default(),
            alarm: None,
            read: 0,
            searched: 0,
        }
    }

    /// A job is under way: the string-art job started and is not done, or
    /// a print from the card is running.
    fn job_under_way(&self) -> Option<String> {
        if self.print.running && !self.print.done {
            let name = self.print.opened.as_deref().unwrap_or("a file");
            return Some(format!("printing {name} from the card"));
        }
        match (&self.operator.state, self.operator.finished) {
            (Some(state), false) => Some(match &self.operator.progress {
                Some((phase, done, total)) => format!("{phase} {done}/{total} ({state})"),
                None => format!("state {state}"),
            }),
            _ => None,
        }
    }

    fn job_done(&self) -> bool {
        self.operator.finished || self.print.done
    }

    /// Reads the complete serial lines that arrived: the print's state
    /// and alarms.
    fn read_lines(&mut self) {
        let bytes = self.sim.uart_bytes();
        let Some(end) = bytes[self.read..].iter().rposition(|&b| b == b'\n') else {
            return;
        };
        let text = String::from_utf8_lossy(&bytes[self.read..self.read + end]).into_owned();
        self.read += end + 1;
        for line in text.lines().map(str::trim) {
            if let Some(rest) = line.strip_prefix("File opened: ") {
                self.print.opened = Some(rest.split(" Size:").next().unwrap_or(rest).to_string());
            } else if line == "File selected" {
                self.print.running = true;
                self.print.done = false;
            } else if line == "Done printing file" {
                self.print.done = true;
            } else if line.starts_with("ALARM:") && self.alarm.is_none() {
                self.alarm = Some(line.to_string());
            } else if let Some(msg) = crate::operator::message(line) {
                if msg.starts_with("print stopped") || msg.starts_with("print aborted") {
                    self.print.running = false;
                }
            }
        }
    }

    /// Runs the plan to its ending. `each` sees what the operator read
    /// after every slice (progress bars, echo); `stop` ends the run when
    /// set (a signal); `pty`, if given, serves the serial port meanwhile.
    pub fn run(
        &mut self,
        plan: &Plan,
        mut pty: Option<&mut Pty>,
        stop: &AtomicBool,
        mut each: impl FnMut(&Sim, &[Seen]),
    ) -> std::io::Result<Ending> {
        let mut cut_at = match plan.cut {
            Some(Cut::At(c)) => Some(c),
            _ => None,
        };
        loop {
            if stop.load(Ordering::Relaxed) {
                return Ok(Ending::Stopped);
            }
            let now = self.sim.cycles();
            if let Some(c) = cut_at {
                if now >= c {
                    return Ok(Ending::PowerCut { cycle: c });
                }
            }
            let text_pending = match (&plan.cut, cut_at) {
                (Some(Cut::On { text, .. }), None) => Some(text.clone()),
                _ => None,
            };
            // The limit and the job's end count only while no cut is
            // planned: the run lasts until the cut.
            if cut_at.is_none() {
                let limit_reached = plan.limit.is_some_and(|l| now >= l);
                let job_ended = plan.auto_confirm && self.job_done();
                if limit_reached || job_ended {
                    if let Some(text) = text_pending {
                        return Ok(Ending::CutMissed { text });
                    }
                    let job = self.job_under_way();
                    let finished = job_ended || (plan.file_sent && job.is_none());
                    return Ok(match finished {
                        true => Ending::JobFinished,
                        false => Ending::Limit { job },
                    });
                }
                if let (Some(line), Some(_)) = (&self.alarm, self.job_under_way()) {
                    return Ok(Ending::Alarm { line: line.clone() });
                }
            }
            let mut end = now + SLICE;
            match cut_at {
                Some(c) => end = end.min(c),
                None => {
                    if let Some(l) = plan.limit {
                        end = end.min(l.max(now + 1));
                    }
                }
            }
            let span = end - now;
            let outcome = match (&mut pty, &text_pending) {
                (Some(pty), _) => match pty.serve(self.sim, crate::clock::duration_of(span))? {
                    // A watchdog reset, or the awaited text: nothing here.
                    o if o.is_fatal() => o,
                    _ => Outcome::Running,
                },
                (None, Some(text)) => {
                    let needle = text.as_bytes().to_vec();
                    let mut searched = self.searched;
                    let o = self.sim.run_until_cycles(
                        |s| {
                            let tx = s.uart_bytes();
                            let from = serial::resume_from(searched.min(tx.len()), needle.len());
                            searched = tx.len();
                            serial::contains(&tx[from..], &needle)
                        },
                        span,
                    );
                    self.searched = searched;
                    o
                }
                (None, None) if cut_at == Some(end) => self.sim.run_to(end),
                (None, None) => self.sim.run_cycles(span),
            };
            if let (Some(Cut::On { text, delay }), None) = (&plan.cut, cut_at) {
                // Found at its last byte (`Done`), or, serving a pty, by
                // the span's end: the cut planned from the cycle seen.
                let found = outcome == Outcome::Done || {
                    let tx = self.sim.uart_bytes();
                    let from = serial::resume_from(self.searched.min(tx.len()), text.len());
                    let found = serial::contains(&tx[from..], text.as_bytes());
                    self.searched = tx.len();
                    found
                };
                if found {
                    cut_at = Some(self.sim.cycles() + delay);
                }
            }
            if outcome.is_fatal() {
                return Ok(Ending::Fault(outcome));
            }
            self.read_lines();
            let seen = self.operator.step(self.sim);
            each(self.sim, &seen);
        }
    }
}
