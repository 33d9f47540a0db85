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
                found = reply_after(s.uart_bytes(), start);
                found.is_some()
            },
            timeout,
        );
        found.ok_or(SendError::NoReply(out))
    }
}

/// The first `ok` / `error:` reply line of `out` that ends past byte
/// `start`; a line under way at `start` is judged whole. Every other line
/// (log lines, the status reports `<…>` a `?` asks for, a banner) is
/// skipped, and so is a line not yet ended. An error comes as Grbl's
/// bare `error:<code>` after its `[MSG:<text>]` line: the reply is read
/// as `error:<code> <text>`.
fn reply_after(out: &[u8], start: usize) -> Option<Reply> {
    let from = out[..start]
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    let mut before: &[u8] = b"";
    let lines = out[from..].split_inclusive(|&b| b == b'\n');
    for l in lines {
        let l = l.strip_suffix(b"\n").map(<[u8]>::trim_ascii_end)?;
        if l == b"ok" {
            return Some(Reply::Ok);
        }
        if l.starts_with(b"error:") {
            let mut text = String::from_utf8_lossy(l).into_owned();
            if let Some(m) = before
                .strip_prefix(b"[MSG:")
                .and_then(|m| m.strip_suffix(b"]"))
            {
                text = format!("{text} {}", String::from_utf8_lossy(m));
            }
            return Some(Reply::Error(text));
        }
        before = l;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replies_are_found_among_log_lines() {
        let reply = |text: &[u8]| reply_after(text, 0);
        assert_eq!(reply(b"[I 1 x] hello\nok\n"), Some(Reply::Ok));
        assert_eq!(
            reply(b"[I 1 x] hello\nok"),
            None,
            "an unfinished line is no reply"
        );
        assert_eq!(
            reply(b"[MSG:Unsupported command (col 1)]\r\nerror:20\r\n"),
            Some(Reply::Error("error:20 Unsupported command (col 1)".into()))
        );
        assert_eq!(reply(b"[I 1 look] ok\n"), None);
    }

    #[test]
    fn status_reports_and_lines_under_way_are_no_replies() {
        let out = b"ok\r\n<Idle|MPos:0.000,1.000,0.000>\r\n<Run|MPos:0.5";
        assert_eq!(reply_after(out, 4), None, "the earlier line's ok");
        let out = [&out[..], b",0.000,0.000>\r\nok\r\n"].concat();
        assert_eq!(reply_after(&out, 4), Some(Reply::Ok));
        // A status report under way when the line was sent is judged whole,
        // even one whose tail looks like a reply.
        let out = b"<Idle|MPos:0.000,1.000,0.000,ok\n>\n";
        assert_eq!(reply_after(out, out.len() - 5), None);
        assert_eq!(
            reply_after(b"[I 2 job] state: \xff\nok\n", 3),
            Some(Reply::Ok)
        );
    }
}
