//! `taut studio`'s machine endpoints against the release image in simavr
//! (`--sim`, its port a pseudo-terminal opened as any serial port), called
//! in-process: connect, console lines and their replies, real-time bytes,
//! a run with its counts, pause, resume and stop, a broken file refused
//! with nothing sent, and a lost connection (the simulator ended): shown
//! at once, the run interrupted at its last acknowledged line, nothing
//! sent again.

use axum::body::Body;
use axum::http::Request;
use http_body_util::BodyExt;
use serde_json::Value;
use std::time::{Duration, Instant};
use taut_logic::machine::Machine;
use taut_studio::app::{self, Options};
use tower::ServiceExt;

async fn call(app: &axum::Router, method: &str, uri: &str, body: &str) -> (u16, Value) {
    let req = Request::builder()
        .method(method)
        .uri(uri)
        .header("x-taut-client", "script")
        .body(Body::from(body.to_string()))
        .unwrap();
    let res = app.clone().oneshot(req).await.unwrap();
    let status = res.status().as_u16();
    let bytes = res.into_body().collect().await.unwrap().to_bytes();
    (
        status,
        serde_json::from_slice(&bytes).unwrap_or(Value::Null),
    )
}

async fn ok(app: &axum::Router, method: &str, uri: &str, body: &str) -> Value {
    let (status, v) = call(app, method, uri, body).await;
    assert_eq!(status, 200, "{method} {uri}: {v}");
    v
}

/// Polls `GET /api/run` until `state`.
async fn run_until(app: &axum::Router, state: &str, limit: Duration) -> Value {
    let until = Instant::now() + limit;
    loop {
        let r = ok(app, "GET", "/api/run", "").await;
        if r["state"] == state {
            return r;
        }
        assert!(Instant::now() < until, "waited for {state}: {r}");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// An interrupted run's reason, which must start with `why`.
fn reason<'a>(run: &'a Value, why: &str) -> &'a str {
    assert_eq!(run["state"], "interrupted", "{run}");
    let reason = run["reason"].as_str().unwrap();
    assert!(reason.starts_with(why), "{reason}");
    reason
}

/// The lines sent, in a `GET /api/machine` answer's log.
fn sent(machine: &Value) -> usize {
    let log = machine["log"].as_array().unwrap();
    log.iter().filter(|l| l["dir"] == "tx").count()
}

/// A square of 40 mm drawn in 1 mm moves: long enough to pause in.
fn square() -> String {
    let mut g = String::from("G21\nG90\nM17\nM5\nG0 X10 Y10\nM3\nG1 F2400\n");
    for k in 1..=160 {
        let (x, y) = match k {
            0..=40 => (10 + k, 10),
            41..=80 => (50, 10 + k - 40),
            81..=120 => (50 - (k - 80), 50),
            _ => (10, 50 - (k - 120)),
        };
        g += &format!("G1 X{x} Y{y}\n");
    }
    g + "M5\nG0 X0 Y0\n"
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_machine_endpoints_drive_the_simulated_flatbed() {
    let o = Options {
        port: 0,
        sim: Some(hil_tests::firmware_elf()),
        machine: Machine::Flatbed,
        ..Options::default()
    };
    let started = app::start(o).await.unwrap();
    let sim = started.simulator().unwrap();
    let app = started.router();
    let ports = ok(&app, "GET", "/api/ports", "").await;
    let tty = sim.tty.display().to_string();
    assert_eq!(ports[0]["path"], tty.as_str());
    assert_eq!(ports[0]["what"], "simulated Mega (release image)");

    // Connect: a status report, then the settings read ($$).
    let m = ok(&app, "POST", &format!("/api/connect?port={tty}"), "").await;
    assert_eq!(m["connected"], true);
    assert!(
        m["settings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|s| s == "$machine=flatbed"),
        "{m}"
    );
    let (status, again) = call(&app, "POST", &format!("/api/connect?port={tty}"), "").await;
    assert_eq!(status, 409, "{again}");

    // Console lines and their replies.
    let r = ok(&app, "POST", "/api/machine/line", "$I").await;
    assert!(
        r["replies"][0]
            .as_str()
            .unwrap()
            .starts_with("[VER:1.1h.taut"),
        "{r}"
    );
    assert_eq!(r["replies"].as_array().unwrap().last().unwrap(), "ok");
    let r = ok(&app, "POST", "/api/machine/line", "?").await;
    assert!(
        r["replies"][0].as_str().unwrap().starts_with("<Idle|MPos:"),
        "{r}"
    );
    let r = ok(&app, "POST", "/api/machine/line", "G1 X900 F100").await;
    assert_eq!(r["replies"].as_array().unwrap().last().unwrap(), "error:15");
    assert!(
        r["words"][0]
            .as_str()
            .unwrap()
            .contains("outside the machine's travel"),
        "{r}"
    );
    let (status, v) = call(&app, "POST", "/api/machine/line", "G0 X1\nG0 X2").await;
    assert_eq!(
        (status, v["error"].as_str().unwrap()),
        (400, "one line at a time")
    );
    let m = ok(&app, "GET", "/api/machine", "").await;
    assert_eq!(m["simulator"], "flatbed");
    assert!(m["log"]
        .as_array()
        .unwrap()
        .iter()
        .any(|l| l["dir"] == "tx" && l["text"] == "$I"));

    // A broken file: refused with where and why, nothing sent.
    let sent_before = sent(&m);
    let (status, v) = call(
        &app,
        "POST",
        "/api/run?name=bad",
        "G21\nG1 X10 F600\nG1 X200\n",
    )
    .await;
    assert_eq!(status, 400);
    assert_eq!(
        v["error"],
        "the G-code, line 3: error:15 Travel exceeded (soft limit): nothing was sent to the flatbed"
    );
    let m = ok(&app, "GET", "/api/machine", "").await;
    assert_eq!(sent_before, sent(&m), "a line went out");

    // A run: counts, pause (the machine holds), resume, the end.
    let r = ok(&app, "POST", "/api/run?name=square", &square()).await;
    assert_eq!(
        (r["state"].as_str(), r["of"].as_u64()),
        (Some("running"), Some(169))
    );
    assert!(r["estimate_s"].as_f64().unwrap() > 3.0, "{r}");
    let (status, v) = call(&app, "POST", "/api/machine/line", "$$").await;
    assert_eq!(
        (status, v["error"].as_str().unwrap()),
        (409, "a run is sending: pause it or stop it first")
    );
    let (status, _) = call(&app, "POST", "/api/run", "G0 X1\n").await;
    assert_eq!(status, 409, "a second run");
    tokio::time::sleep(Duration::from_millis(1500)).await;
    let r = ok(&app, "POST", "/api/run/pause", "").await;
    assert_eq!(r["state"], "paused");
    let until = Instant::now() + Duration::from_secs(5);
    while ok(&app, "GET", "/api/machine", "").await["status"]["state"] != "Hold:0" {
        assert!(Instant::now() < until, "not held");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let held = ok(&app, "GET", "/api/machine", "").await["status"]["mpos"].clone();
    tokio::time::sleep(Duration::from_millis(600)).await;
    assert_eq!(
        ok(&app, "GET", "/api/machine", "").await["status"]["mpos"],
        held
    );
    let r = ok(&app, "POST", "/api/run/resume", "").await;
    assert_eq!(r["state"], "running");
    let r = run_until(&app, "done", Duration::from_secs(60)).await;
    assert_eq!(
        (r["line"].as_u64(), r["of"].as_u64(), r["percent"].as_f64()),
        (Some(169), Some(169), Some(100.0))
    );
    assert_eq!(r["errors"].as_array().unwrap().len(), 0);
    let (status, _) = call(&app, "POST", "/api/run/resume", "").await;
    assert_eq!(status, 409, "nothing to resume");

    // Stop: Ctrl-X, the run interrupted at its last acknowledged line.
    // Stopped while drawing the square's first side (not while the pen
    // goes down, when the machine stands and keeps its position).
    ok(&app, "POST", "/api/run?name=square", &square()).await;
    let until = Instant::now() + Duration::from_secs(10);
    loop {
        let s = ok(&app, "GET", "/api/machine", "").await["status"].clone();
        if s["state"] == "Run" && s["mpos"][0].as_f64().unwrap_or(0.0) > 12.0 {
            break;
        }
        assert!(Instant::now() < until, "not drawing: {s}");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    let r = ok(&app, "POST", "/api/run/stop", "").await;
    reason(
        &r,
        "stopped: Ctrl-X sent, the machine reset (last acknowledged line: ",
    );
    // The machine lost its position (ALARM:3) and says what to do.
    let until = Instant::now() + Duration::from_secs(3);
    loop {
        let m = ok(&app, "GET", "/api/machine", "").await;
        let notice = m["notice"].as_str().unwrap_or_default();
        if notice.starts_with("ALARM:3") {
            assert!(notice.contains("unlock ($X)"), "{notice}");
            break;
        }
        let log: Vec<&Value> = m["log"].as_array().unwrap().iter().rev().take(12).collect();
        assert!(
            Instant::now() < until,
            "{notice}\nstatus {}\n{log:#?}",
            m["status"]
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    ok(&app, "POST", "/api/machine/line", "$X").await;
    ok(&app, "POST", "/api/machine/realtime?cmd=status", "").await;

    // The power cut mid-run (the simulator's): the board starts again
    // behind the same terminal, the run is over at its last acknowledged
    // line, nothing is sent again.
    ok(&app, "POST", "/api/run?name=square", &square()).await;
    tokio::time::sleep(Duration::from_millis(800)).await;
    let r = ok(&app, "POST", "/api/sim/power_cut", "").await;
    assert_eq!(r["power_cuts"], 1);
    let r = run_until(&app, "interrupted", Duration::from_secs(5)).await;
    reason(&r, "the machine reset (last acknowledged line: ");
    let until = Instant::now() + Duration::from_secs(30);
    loop {
        let m = ok(&app, "GET", "/api/machine", "").await;
        assert_eq!(m["connected"], true);
        if matches!(m["status"]["state"].as_str(), Some("Idle" | "Alarm")) {
            break;
        }
        assert!(Instant::now() < until, "not back: {}", m["status"]);
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let sent_then = sent(&ok(&app, "GET", "/api/machine", "").await);
    tokio::time::sleep(Duration::from_millis(500)).await;
    let m = ok(&app, "GET", "/api/machine", "").await;
    assert_eq!(sent(&m), sent_then, "sent again after the cut");
    ok(&app, "POST", "/api/machine/line", "$X").await;

    // The simulator ends mid-run: the link is lost at once, the run
    // interrupted at its last acknowledged line, nothing sent again.
    ok(&app, "POST", "/api/run?name=square", &square()).await;
    tokio::time::sleep(Duration::from_millis(800)).await;
    let acked = ok(&app, "GET", "/api/run", "").await["last_acknowledged"]
        .as_u64()
        .unwrap();
    let ended = Instant::now();
    sim.stop().unwrap();
    let r = run_until(&app, "interrupted", Duration::from_secs(2)).await;
    let shown = ended.elapsed();
    let reason = reason(&r, &format!("connection to {tty} lost"));
    let last: u64 = reason
        .rsplit(": ")
        .next()
        .unwrap()
        .trim_end_matches(')')
        .parse()
        .unwrap();
    assert!(last >= acked, "{reason}");
    let m = ok(&app, "GET", "/api/machine", "").await;
    assert_eq!(
        (m["connected"].clone(), m["status"]["state"].clone()),
        (false.into(), "Disconnected".into())
    );
    assert!(m["lost"].as_str().unwrap().starts_with("connection to"));
    let (status, v) = call(&app, "POST", "/api/run/resume", "").await;
    assert_eq!(
        (status, v["error"].as_str().unwrap()),
        (409, "no run is going")
    );
    eprintln!("studio app: the lost link shown in {shown:?}; {reason}");
    assert!(shown < Duration::from_secs(1), "{shown:?}");
}
