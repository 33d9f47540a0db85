//! The machine as the app knows it: the serial link, what the machine said
//! (its last status report, the console's log, its `$$` listing), the
//! console line waiting for its answer, the run and the string-art job.
//! Every change goes out on the event stream as one JSON object.
//!
//! One lock (`Inner`) guards it all; it is held only for what a reply or a
//! request changes, never across an `await`.

use super::link::{Link, Listener};
use super::run::Run;
use super::words;
use serde::Serialize;
use serde_json::{json, Value};
use std::collections::VecDeque;
use std::sync::{Arc, Mutex, MutexGuard};
use tokio::sync::{broadcast, oneshot};

/// Lines of the console kept for a page that opens late.
const LOG_LINES: usize = 400;

#[derive(Clone, Debug, Default, Serialize)]
pub struct Status {
    /// `Idle`, `Run`, `Hold:0`, `Alarm`, … or `Disconnected`.
    pub state: String,
    /// Machine position, mm (or degrees), as reported.
    pub mpos: Vec<f64>,
    /// Free planner blocks and receive bytes (`Bf:`).
    pub buffer: Option<[u32; 2]>,
    /// The report as it came.
    pub raw: String,
}

impl Status {
    /// `<Idle|MPos:0.000,-200.000,0.000|Bf:12,128>`.
    pub fn parse(line: &str) -> Option<Status> {
        let body = line.strip_prefix('<')?.strip_suffix('>')?;
        let mut fields = body.split('|');
        let mut s = Status {
            state: fields.next()?.to_string(),
            raw: line.to_string(),
            ..Status::default()
        };
        let numbers =
            |v: &str| -> Vec<f64> { v.split(',').filter_map(|n| n.parse().ok()).collect() };
        for f in fields {
            match f.split_once(':') {
                Some(("MPos", v)) => s.mpos = numbers(v),
                Some(("Bf", v)) => {
                    let n = numbers(v);
                    if n.len() == 2 {
                        s.buffer = Some([n[0] as u32, n[1] as u32]);
                    }
                }
                _ => {}
            }
        }
        Some(s)
    }
}

/// A line of the console: sent (`tx`), received (`rx`) or the app's own
/// note (`note`); errors and alarms carry their plain words.
#[derive(Clone, Debug, Serialize)]
pub struct LogLine {
    pub n: u64,
    pub dir: &'static str,
    pub text: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub words: Option<String>,
}

/// The string-art job as its log lines tell it.
#[derive(Clone, Debug, Default, Serialize)]
pub struct JobStatus {
    pub state: Option<String>,
    /// The prompt waiting for an answer (`>>> …`), until the state moves.
    pub prompt: Option<String>,
    /// `drill` or `wind`, done, of.
    pub progress: Option<(String, u32, u32)>,
    /// The job's last error line.
    pub error: Option<String>,
    /// What the boot found of a job a reset stopped (`checkpoint: winding
    /// stopped at 12/40 by a reset: power-on`).
    pub checkpoint: Option<String>,
}

impl JobStatus {
    /// Reads one `[MSG:I 12 job: …]` line; whether it was the job's.
    fn read(&mut self, line: &str) -> bool {
        let Some(msg) = message(line) else {
            return false;
        };
        let module = line[5..]
            .split(": ")
            .next()
            .and_then(|h| h.rsplit(' ').next());
        if module == Some("checkpoint") || msg.starts_with("checkpoint: ") {
            let what = msg.trim_start_matches("checkpoint: ");
            self.checkpoint = Some(format!("checkpoint: {what}"));
        } else if let Some(state) = msg.strip_prefix("state: ") {
            self.state = Some(state.to_string());
            self.prompt = None;
        } else if msg.starts_with(">>> ") {
            self.prompt = Some(msg.to_string());
        } else if let Some(p) = progress(msg) {
            self.progress = Some(p);
        } else if line.starts_with("[MSG:E") {
            self.error = Some(msg.to_string());
        } else {
            return false;
        }
        true
    }
}

/// The text of a log line `[MSG:I 123 module: text]`.
fn message(line: &str) -> Option<&str> {
    let rest = line.strip_prefix("[MSG:")?.strip_suffix(']')?;
    Some(rest.split_once(": ")?.1)
}

/// `drill 3/24` or `wind 1234/3000 left 12s`.
fn progress(msg: &str) -> Option<(String, u32, u32)> {
    let (phase, rest) = msg.split_once(' ')?;
    let counts = rest.split(' ').next()?;
    let (done, of) = counts.split_once('/')?;
    match phase {
        "drill" | "wind" => Some((phase.to_string(), done.parse().ok()?, of.parse().ok()?)),
        _ => None,
    }
}

/// A console line waiting for its answer: every line up to its `ok` or
/// `error:` (or, for a `?`, the next status report).
struct Waiter {
    replies: Vec<String>,
    status_only: bool,
    done: oneshot::Sender<Result<Vec<String>, String>>,
}

pub struct Inner {
    pub link: Option<Arc<Link>>,
    pub status: Status,
    /// Why the last connection ended, if it was lost.
    pub lost: Option<String>,
    log: VecDeque<LogLine>,
    logged: u64,
    waiter: Option<Waiter>,
    pub run: Option<Run>,
    pub job: JobStatus,
    /// The last `$$` listing's lines (`$x_max_rate=2000`).
    pub settings: Vec<String>,
    /// The client id that controls the machine.
    pub controller: Option<String>,
    /// Open event streams per client id.
    pub watchers: Vec<String>,
    /// The last error or alarm in plain words.
    pub notice: Option<String>,
}

pub struct Hub {
    inner: Mutex<Inner>,
    events: broadcast::Sender<String>,
}

impl Hub {
    pub fn new() -> Arc<Hub> {
        Arc::new(Hub {
            inner: Mutex::new(Inner {
                link: None,
                status: Status {
                    state: "Disconnected".into(),
                    ..Status::default()
                },
                lost: None,
                log: VecDeque::new(),
                logged: 0,
                waiter: None,
                run: None,
                job: JobStatus::default(),
                settings: Vec::new(),
                controller: None,
                watchers: Vec::new(),
                notice: None,
            }),
            events: broadcast::channel(1024).0,
        })
    }

    pub fn lock(&self) -> MutexGuard<'_, Inner> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub fn subscribe(&self) -> broadcast::Receiver<String> {
        self.events.subscribe()
    }

    pub fn emit(&self, kind: &str, body: Value) {
        let mut event = json!({ "type": kind });
        if let (Some(e), Value::Object(b)) = (event.as_object_mut(), body) {
            e.extend(b);
        }
        let _ = self.events.send(event.to_string());
    }

    /// Everything a page needs when it opens (and `GET /api/machine`).
    pub fn snapshot(&self) -> Value {
        let inner = self.lock();
        json!({
            "connected": inner.link.is_some(),
            "port": inner.link.as_ref().map(|l| l.name.clone()),
            "lost": inner.lost,
            "status": inner.status,
            "log": inner.log,
            "job": inner.job,
            "settings": inner.settings,
            "controller": inner.controller,
            "notice": inner.notice,
            "run": inner.run.as_ref().map(Run::report),
        })
    }

    /// Adds a console line (and sends it out as an event).
    pub fn log(&self, inner: &mut Inner, dir: &'static str, text: &str) {
        inner.logged += 1;
        let words = match dir {
            "rx" => words::explain(text),
            _ => None,
        };
        if words.is_some() {
            inner.notice.clone_from(&words);
        }
        let line = LogLine {
            n: inner.logged,
            dir,
            text: text.to_string(),
            words,
        };
        self.emit("log", json!({ "line": line }));
        inner.log.push_back(line);
        if inner.log.len() > LOG_LINES {
            inner.log.pop_front();
        }
    }

    /// Writes `bytes` to the machine; a failed write is a lost link.
    pub fn write(&self, inner: &mut Inner, bytes: &[u8]) -> Result<(), String> {
        let link = inner.link.clone().ok_or("not connected")?;
        link.write(bytes).inspect_err(|e| self.lost(inner, e))
    }

    /// One line from the machine (the link's reader calls this).
    pub fn on_line(&self, line: &str) {
        let mut inner = self.lock();
        let inner = &mut *inner;
        if let Some(status) = Status::parse(line) {
            let asked = inner.waiter.as_ref().is_some_and(|w| w.status_only);
            if asked {
                self.log(inner, "rx", line);
                if let Some(w) = inner.waiter.take() {
                    let _ = w.done.send(Ok(vec![line.to_string()]));
                }
            }
            inner.status = status;
            self.emit("status", json!({ "status": inner.status }));
            if let Some(run) = inner.run.as_mut() {
                if run.on_status(&inner.status.state) {
                    self.emit("run", run.report());
                }
            }
            return;
        }
        self.log(inner, "rx", line);
        if inner.job.read(line) {
            self.emit("job", json!({ "job": inner.job }));
        }
        if let Some(setting) = line.strip_prefix('$').filter(|l| l.contains('=')) {
            remember_setting(&mut inner.settings, setting);
        }
        if line.starts_with("Grbl ") {
            if let Some(w) = inner.waiter.take() {
                let _ = w.done.send(Err("the machine reset".into()));
            }
            // A reset ends the job the page knew; the boot tells anew.
            inner.job = JobStatus::default();
            self.emit("job", json!({ "job": inner.job }));
        }
        // A run takes every answer; otherwise the console's waiting line.
        if inner.run.as_ref().is_some_and(Run::active) {
            self.run_reply(inner, line);
        } else if let Some(w) = inner.waiter.as_mut().filter(|w| !w.status_only) {
            w.replies.push(line.to_string());
            if line == "ok" || line.starts_with("error:") || line.starts_with("ALARM:") {
                let w = inner.waiter.take().expect("just seen");
                let _ = w.done.send(Ok(w.replies));
            }
        }
    }

    fn run_reply(&self, inner: &mut Inner, line: &str) {
        let Some(run) = inner.run.as_mut() else {
            return;
        };
        let notes = run.on_reply(line);
        let mut out = Vec::new();
        if run.active() {
            if let Err(e) = run.fill(&mut out) {
                run.interrupt(&e);
            }
        }
        let report = run.report();
        for note in notes {
            self.log(inner, "note", &note);
        }
        for sent in out {
            let text = String::from_utf8_lossy(&sent).trim_end().to_string();
            if let Err(e) = self.write(inner, &sent) {
                let _ = e;
                break;
            }
            self.log(inner, "tx", &text);
        }
        self.emit("run", report);
    }

    /// A console line: waits for its answer. `?` alone waits for the next
    /// status report; a line gets every reply up to its `ok` / `error:`.
    pub async fn console(
        &self,
        line: &str,
        wait: std::time::Duration,
    ) -> Result<Vec<String>, String> {
        let (tx, rx) = oneshot::channel();
        {
            let mut inner = self.lock();
            let inner = &mut *inner;
            if inner.link.is_none() {
                return Err("not connected".into());
            }
            if inner.run.as_ref().is_some_and(Run::active) {
                return Err("a run is sending: pause it or stop it first".into());
            }
            if inner.waiter.is_some() {
                return Err("the console waits for the answer to the line before".into());
            }
            let status_only = line == "?";
            inner.waiter = Some(Waiter {
                replies: Vec::new(),
                status_only,
                done: tx,
            });
            let bytes = match status_only {
                true => b"?".to_vec(),
                false => format!("{line}\n").into_bytes(),
            };
            if let Err(e) = self.write(inner, &bytes) {
                inner.waiter = None;
                return Err(e);
            }
            self.log(inner, "tx", line);
        }
        match tokio::time::timeout(wait, rx).await {
            Ok(Ok(answer)) => answer,
            Ok(Err(_)) => Err("the connection ended before the answer".into()),
            Err(_) => {
                self.lock().waiter = None;
                Err(format!("no answer within {} s", wait.as_secs()))
            }
        }
    }

    /// The link failed: shown at once, a run interrupted at its last
    /// acknowledged line, a waiting console line answered with the error.
    pub fn lost(&self, inner: &mut Inner, why: &str) {
        let Some(link) = inner.link.take() else {
            return;
        };
        link.close();
        let why = format!("connection to {} lost: {why}", link.name);
        inner.lost = Some(why.clone());
        inner.status = Status {
            state: "Disconnected".into(),
            ..Status::default()
        };
        if let Some(w) = inner.waiter.take() {
            let _ = w.done.send(Err(why.clone()));
        }
        if let Some(run) = inner.run.as_mut().filter(|r| r.active()) {
            run.interrupt(&why);
            self.emit("run", run.report());
        }
        self.log(inner, "note", &why);
        self.emit(
            "link",
            json!({ "connected": false, "port": Value::Null, "lost": why }),
        );
        self.emit("status", json!({ "status": inner.status }));
    }

    pub fn lost_now(&self, why: &str) {
        let mut inner = self.lock();
        self.lost(&mut inner, why);
    }
}

/// Keeps `name=value` from a `$$` line, replacing an earlier one.
fn remember_setting(settings: &mut Vec<String>, setting: &str) {
    let key = setting.split('=').next().unwrap_or_default();
    let line = format!("${setting}");
    match settings
        .iter_mut()
        .find(|s| s[1..].split('=').next() == Some(key))
    {
        Some(old) => *old = line,
        None => settings.push(line),
    }
}

impl Listener for Hub {
    fn on_line(&self, line: &str) {
        Hub::on_line(self, line)
    }
    fn lost_now(&self, why: &str) {
        Hub::lost_now(self, why)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn status_reports_job_lines_and_settings_are_read() {
        let s = Status::parse("<Hold:0|MPos:1.500,-2.000,0.000|Bf:12,127|FS:0,0>").unwrap();
        assert_eq!(s.state, "Hold:0");
        assert_eq!(s.mpos, [1.5, -2.0, 0.0]);
        assert_eq!(s.buffer, Some([12, 127]));
        assert!(Status::parse("ok").is_none());
        let mut job = JobStatus::default();
        assert!(job.read("[MSG:I 120 job: state: drilling]"));
        assert!(job.read("[MSG:I 121 job: >>> zero, drill on, press green to drill]"));
        assert!(job.read("[MSG:I 122 job: drill 3/24]"));
        assert_eq!(job.progress, Some(("drill".into(), 3, 24)));
        assert_eq!(
            job.prompt.as_deref(),
            Some(">>> zero, drill on, press green to drill")
        );
        assert!(job.read("[MSG:I 123 job: state: winding]"));
        assert_eq!(job.prompt, None);
        assert!(!job.read("[MSG:Caution: Unlocked]"));
        assert!(job.read("[MSG:W 9 checkpoint: winding stopped at 4/40 by a reset: power-on]"));
        assert_eq!(
            job.checkpoint.as_deref(),
            Some("checkpoint: winding stopped at 4/40 by a reset: power-on")
        );
        let mut settings = vec!["$machine=flatbed".to_string()];
        remember_setting(&mut settings, "x_max_rate=2000");
        remember_setting(&mut settings, "machine=drum");
        assert_eq!(settings, ["$machine=drum", "$x_max_rate=2000"]);
    }
}
