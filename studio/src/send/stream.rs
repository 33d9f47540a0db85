//! Character counting, Grbl's way, as a state machine that neither reads
//! nor writes: the caller hands it each reply and writes what it says to.
//! `taut send` drives it from its terminal loop, `taut studio` from the
//! machine link's reader; one stream logic for both.

use std::collections::VecDeque;

/// Grbl 1.1's receive buffer; senders keep one byte of it free, as Grbl's
/// own stream.py and grbl-streamer do (bytes of lines sent and not yet
/// answered stay under it).
pub const RX_BUFFER: usize = 128;

/// The lines sent and not yet answered, oldest first (index into the
/// file's lines, bytes with the newline). Grbl answers in order, so each
/// `ok` or `error:` frees the oldest.
#[derive(Default)]
pub(super) struct Window {
    pub(super) in_flight: VecDeque<(usize, usize)>,
    pub(super) bytes: usize,
}

impl Window {
    /// `line` (without its newline) fits beside the bytes in flight.
    pub(super) fn fits(&self, line: &str) -> bool {
        self.bytes + line.len() + 1 < RX_BUFFER
    }

    pub(super) fn sent(&mut self, index: usize, line: &str) {
        self.in_flight.push_back((index, line.len() + 1));
        self.bytes += line.len() + 1;
    }

    /// A reply came: the index of the line it answers.
    pub(super) fn answered(&mut self) -> Option<usize> {
        let (i, n) = self.in_flight.pop_front()?;
        self.bytes -= n;
        Some(i)
    }
}

/// The file's lines as sent, each with its line number: blanks, `%` tape
/// marks and comments (`( … )`, `;` to the end) kept home, and G-code's
/// spaces too, as Grbl's stream.py does (every byte in flight is a byte of
/// the 128); `$` lines only trimmed (their values are text).
pub fn lines_of(text: &[u8]) -> Vec<(usize, String)> {
    String::from_utf8_lossy(text)
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, clean(l)))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('%'))
        .collect()
}

fn clean(line: &str) -> String {
    let mut code = String::new();
    let mut in_comment = false;
    for c in line.chars() {
        match c {
            _ if in_comment => in_comment = c != ')',
            '(' => in_comment = true,
            ';' => break,
            c => code.push(c),
        }
    }
    let code = code.trim();
    match code.starts_with('$') && !code.starts_with("$J=") {
        true => code.to_string(),
        false => code.chars().filter(|c| !c.is_whitespace()).collect(),
    }
}

/// What a reply meant to the stream.
#[derive(Clone, Debug, PartialEq)]
pub enum Answer {
    /// The line at `index` (into [`Stream::lines`]) was answered; with the
    /// reply and the firmware's words (its `[MSG:…]` before) if refused.
    Line { index: usize, error: Option<String> },
    /// `ALARM:n` and the firmware's words: the stream must stop.
    Alarm(String),
    /// Not an answer (a status report, a log line).
    Other,
}

/// A file on its way: which lines went, which were answered.
pub struct Stream {
    lines: Vec<(usize, String)>,
    window: Window,
    next: usize,
    answered: usize,
    errors: usize,
    /// The firmware's words for an error or alarm come just before it.
    message: String,
}

impl Stream {
    /// The file's lines; a line longer than the buffer would never fit
    /// beside nothing (the stream would wait for it forever): refused.
    pub fn new(text: &[u8]) -> Result<Stream, String> {
        let lines = lines_of(text);
        if let Some((n, l)) = lines.iter().find(|(_, l)| !Window::default().fits(l)) {
            return Err(format!(
                "line {n}: {} characters, more than Grbl's buffer takes ({}): {l}",
                l.len(),
                RX_BUFFER - 2
            ));
        }
        Ok(Stream {
            lines,
            window: Window::default(),
            next: 0,
            answered: 0,
            errors: 0,
            message: String::new(),
        })
    }

    /// The lines as sent, with their numbers in the file.
    pub fn lines(&self) -> &[(usize, String)] {
        &self.lines
    }

    /// Writes (with `write`) every line that fits beside those in flight.
    pub fn fill<E>(&mut self, mut write: impl FnMut(&[u8]) -> Result<(), E>) -> Result<(), E> {
        while let Some((_, line)) = self.lines.get(self.next) {
            if !self.window.fits(line) {
                break;
            }
            write(format!("{line}\n").as_bytes())?;
            self.window.sent(self.next, line);
            self.next += 1;
        }
        Ok(())
    }

    /// One line from the machine.
    pub fn reply(&mut self, reply: &str) -> Result<Answer, String> {
        if reply == "ok" || reply.starts_with("error:") {
            let index = self
                .window
                .answered()
                .ok_or(format!("a reply with no line sent: {reply}"))?;
            self.answered += 1;
            let error = (reply != "ok").then(|| {
                self.errors += 1;
                format!("{reply} {}", self.message).trim().to_string()
            });
            self.message.clear();
            return Ok(Answer::Line { index, error });
        }
        if reply.starts_with("ALARM:") {
            return Ok(Answer::Alarm(
                format!("{reply} {}", self.message).trim().to_string(),
            ));
        }
        if let Some(m) = reply
            .strip_prefix("[MSG:")
            .and_then(|m| m.strip_suffix(']'))
        {
            self.message = m.to_string();
        }
        Ok(Answer::Other)
    }

    /// Lines written so far.
    pub fn sent(&self) -> usize {
        self.next
    }

    /// Lines answered so far (`ok` or `error:`).
    pub fn answered(&self) -> usize {
        self.answered
    }

    pub fn errors(&self) -> usize {
        self.errors
    }

    /// Every line answered.
    pub fn done(&self) -> bool {
        self.answered == self.lines.len()
    }
}
