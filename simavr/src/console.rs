//! Talking to the firmware's serial console as a G-code sender does: send a
//! line, wait for its `ok` or `error:` reply.

use crate::outcome::Outcome;
use crate::sim::Sim;
use std::time::Duration;

/// How a line was answered.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Reply {
    Ok,
    /// The whole `error:…` line.
    Error(String),
}

/// Why no reply came.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SendError {
    /// No reply within the timeout, or the firmware failed (the outcome).
    NoReply(Outcome),
}

impl Sim {
    /// Send `line` (a newline is added) and run until the firmware answers
    /// it with `ok` or `error:…`. Replies to earlier lines are not counted.
    pub fn send_line(&mut self, line: &str, timeout: Duration) -> Result<Reply, SendError> {
        let start = self.uart_bytes().len();
        self.uart_send(format!("{line}\n").as_bytes());
        let mut found = None;
        let out = self.run_until(
            |s| {
                found = reply_in(&s.uart_bytes()[start..]);
                found.is_some()
            },
            timeout,
        );
        found.ok_or(SendError::NoReply(out))
    }
}

/// The first `ok` / `error:` reply line in `text`.
fn reply_in(text: &[u8]) -> Option<Reply> {
    let text = std::str::from_utf8(text).ok()?;
    let mut lines = text.split_inclusive('\n').filter(|l| l.ends_with('\n'));
    lines.find_map(|l| {
        let l = l.trim_end();
        if l == "ok" {
            Some(Reply::Ok)
        } else if l.starts_with("error:") {
            Some(Reply::Error(l.to_string()))
        } else {
            None
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replies_are_found_among_log_lines() {
        assert_eq!(reply_in(b"[I 1 x] hello\nok\n"), Some(Reply::Ok));
        assert_eq!(
            reply_in(b"[I 1 x] hello\nok"),
            None,
            "an unfinished line is no reply"
        );
        assert_eq!(
            reply_in(b"error:20 Unsupported command (col 1)\n"),
            Some(Reply::Error("error:20 Unsupported command (col 1)".into()))
        );
        assert_eq!(reply_in(b"[I 1 look] ok\n"), None);
    }
}
