//! The HTTP API (`docs/studio.md`): a request's body is the file's bytes,
//! options are query parameters named as the CLI's flags, answers are
//! JSON (`{"error": …}` with a 4xx status when refused). The token rule
//! and the one-controller rule are checked here.

use super::hub::Hub;
use super::link::{self, Link};
use super::run::Run;
use super::tools::{self, Query};
use super::{web, Bad, Studio};
use axum::body::{Body, Bytes};
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::extract::{Path, State};
use axum::http::{header, HeaderMap, Request};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde_json::{json, Value};
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Duration;
use taut_logic::config::MachineConfig;
use taut_logic::pinmap::Button;

type App = Arc<Studio>;
type Answer = Result<Json<Value>, Bad>;

/// The largest upload taken: a picture, an SVG or a G-code file.
pub const UPLOAD_LIMIT: usize = 25 << 20;

pub fn router(app: App) -> Router {
    Router::new()
        .route("/", get(web::index))
        .route("/app.js", get(web::script))
        .route("/style.css", get(web::style))
        .route("/api/machines", get(|| async { Json(tools::machines()) }))
        .route(
            "/api/vectorize",
            post(|u, h, b| tool(u, h, b, tools::vectorize)),
        )
        .route("/api/text", post(|u, h, b| tool(u, h, b, tools::text)))
        .route("/api/gcode", post(|u, h, b| tool(u, h, b, tools::gcode)))
        .route(
            "/api/stringart",
            post(|u, h, b| tool(u, h, b, tools::stringart)),
        )
        .route("/api/template", get(template))
        .route(
            "/api/card",
            post(|u, h, b| tool(u, h, b, tools::write_card)),
        )
        .route("/api/ports", get(ports))
        .route("/api/connect", post(connect_handler))
        .route("/api/disconnect", post(disconnect))
        .route("/api/machine", get(machine))
        .route("/api/machine/line", post(line))
        .route("/api/machine/realtime", post(realtime))
        .route("/api/machine/button", post(button))
        .route("/api/sim/card", post(sim_card))
        .route("/api/sim/power_cut", post(power_cut))
        .route("/api/run", post(run_start).get(run_report))
        .route("/api/run/{action}", post(run_action))
        .route("/api/controller", get(controller).post(take_over))
        .route("/api/events", get(events))
        .fallback(|| async {
            Bad {
                status: 404,
                message: "no such page or API".into(),
            }
        })
        .layer(middleware::from_fn_with_state(app.clone(), guard))
        .with_state(app)
}

/// The token rule: with a token set (any address but 127.0.0.1, or
/// `--token`), every request carries it: `Authorization: Bearer T`,
/// `?token=T`, or the cookie the page got when opened with `?token=T`.
async fn guard(State(app): State<App>, req: Request<Body>, next: Next) -> Response {
    let Some(token) = &app.token else {
        return next.run(req).await;
    };
    let given = |v: &str| same(v.as_bytes(), token.as_bytes());
    let headers = req.headers();
    let bearer = headers
        .get(header::AUTHORIZATION)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.strip_prefix("Bearer "))
        .is_some_and(given);
    let cookie = headers
        .get_all(header::COOKIE)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|v| v.split(';'))
        .filter_map(|c| c.trim().strip_prefix("taut_token="))
        .any(given);
    let query = query_pairs(req.uri());
    let in_query = query.get("token").is_some_and(|t| given(t));
    if !(bearer || cookie || in_query) {
        return Bad {
            status: 401,
            message: "a token is needed: open the address taut studio printed (…/?token=…), \
                      or send Authorization: Bearer TOKEN"
                .into(),
        }
        .into_response();
    }
    let mut response = next.run(req).await;
    if in_query && !cookie {
        let c = format!("taut_token={token}; HttpOnly; SameSite=Strict; Path=/");
        if let Ok(v) = c.parse() {
            response.headers_mut().insert(header::SET_COOKIE, v);
        }
    }
    response
}

/// Equal, in time that does not depend on where they differ.
fn same(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len() && a.iter().zip(b).fold(0u8, |d, (x, y)| d | (x ^ y)) == 0
}

/// The query string's pairs, decoded (serde_urlencoded, through axum).
fn query_pairs(uri: &axum::http::Uri) -> HashMap<String, String> {
    axum::extract::Query::<HashMap<String, String>>::try_from_uri(uri)
        .map(|q| q.0)
        .unwrap_or_default()
}

/// The request's options.
fn options(uri: &axum::http::Uri) -> Query {
    Query(query_pairs(uri))
}

/// The body, at most [`UPLOAD_LIMIT`] bytes, or a clear refusal.
async fn upload(headers: &HeaderMap, body: Body) -> Result<Bytes, Bad> {
    let too_big = |n: Option<usize>| Bad {
        status: 413,
        message: match n {
            Some(n) => format!(
                "the file is {:.1} MB: the studio takes files up to {} MB",
                n as f64 / (1 << 20) as f64,
                UPLOAD_LIMIT >> 20
            ),
            None => format!(
                "the file is over {} MB, the most the studio takes",
                UPLOAD_LIMIT >> 20
            ),
        },
    };
    let declared = headers
        .get(header::CONTENT_LENGTH)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.parse::<usize>().ok());
    if let Some(n) = declared.filter(|&n| n > UPLOAD_LIMIT) {
        return Err(too_big(Some(n)));
    }
    axum::body::to_bytes(body, UPLOAD_LIMIT)
        .await
        .map_err(|_| too_big(None))
}

/// Runs a tool off the async threads (vectorising and generating take
/// seconds).
async fn blocking<T: Send + 'static>(
    f: impl FnOnce() -> Result<T, Bad> + Send + 'static,
) -> Result<T, Bad> {
    tokio::task::spawn_blocking(f).await.map_err(|e| Bad {
        status: 500,
        message: format!("the tool failed: {e}"),
    })?
}

/// A tool's request: the body and the query in, its JSON out.
async fn tool(
    uri: axum::http::Uri,
    headers: HeaderMap,
    body: Body,
    f: fn(&[u8], &Query) -> Result<Value, Bad>,
) -> Answer {
    let bytes = upload(&headers, body).await?;
    let q = options(&uri);
    blocking(move || f(&bytes, &q)).await.map(Json)
}

async fn template(uri: axum::http::Uri) -> Result<Response, Bad> {
    let svg = tools::template(&options(&uri))?;
    Ok((
        [
            (header::CONTENT_TYPE, "image/svg+xml"),
            (
                header::CONTENT_DISPOSITION,
                "attachment; filename=\"template.svg\"",
            ),
        ],
        svg,
    )
        .into_response())
}

async fn ports(State(app): State<App>) -> Json<Value> {
    let sim = app.sim.as_ref().map(|s| s.tty.display().to_string());
    Json(json!(link::ports(sim.as_deref())))
}

/// Who is asking: the page's id (`X-Taut-Client`, or `?client=` on the
/// event stream); a script without one is "".
fn client(headers: &HeaderMap, uri: &axum::http::Uri) -> String {
    headers
        .get("x-taut-client")
        .and_then(|v| v.to_str().ok())
        .map(str::to_string)
        .or_else(|| options(uri).0.remove("client"))
        .unwrap_or_default()
}

/// The caller controls the machine (taking it when nobody does), or is
/// told who does.
fn control(app: &Studio, who: &str) -> Result<(), Bad> {
    let mut inner = app.hub.lock();
    match &inner.controller {
        Some(c) if c != who => Err(Bad::conflict(
            "another window controls the machine: this one watches (take over to act)",
        )),
        Some(_) => Ok(()),
        None => {
            inner.controller = Some(who.to_string());
            app.hub.emit("controller", json!({ "controller": who }));
            Ok(())
        }
    }
}

async fn controller(State(app): State<App>) -> Json<Value> {
    Json(json!({ "controller": app.hub.lock().controller }))
}

/// `POST /api/controller`: take over, explicitly.
async fn take_over(
    State(app): State<App>,
    headers: HeaderMap,
    uri: axum::http::Uri,
) -> Json<Value> {
    let who = client(&headers, &uri);
    app.hub.lock().controller = Some(who.clone());
    app.hub.emit("controller", json!({ "controller": who }));
    Json(json!({ "controller": who }))
}

async fn connect_handler(
    State(app): State<App>,
    headers: HeaderMap,
    uri: axum::http::Uri,
) -> Answer {
    control(&app, &client(&headers, &uri))?;
    let q = options(&uri);
    let port =
        q.0.get("port")
            .cloned()
            .or_else(|| app.sim.as_ref().map(|s| s.tty.display().to_string()))
            .ok_or_else(|| Bad::input("missing port".into()))?;
    connect(&app, &port).await.map(Json)
}

/// Opens `port` and waits for the machine to answer a status request;
/// then reads its settings (`$$`).
pub async fn connect(app: &Studio, port: &str) -> Result<Value, Bad> {
    if let Some(l) = &app.hub.lock().link {
        return Err(Bad::conflict(format!(
            "connected to {} already: disconnect first",
            l.name
        )));
    }
    let link = Link::open(port, app.hub.clone()).map_err(|e| Bad {
        status: 502,
        message: e,
    })?;
    {
        let mut inner = app.hub.lock();
        inner.link = Some(link);
        inner.lost = None;
        inner.status.state = "Connecting".into();
        app.hub
            .emit("link", json!({ "connected": true, "port": port }));
    }
    // A Mega resets as its port opens (its boot loader waits ~1.6 s): up
    // to 5 s for the first status report the poller asks for.
    let mut answered = false;
    for k in 0..50 {
        let (linked, state) = {
            let mut inner = app.hub.lock();
            if k % 3 == 0 && inner.link.is_some() {
                let _ = app.hub.write(&mut inner, b"?");
            }
            (inner.link.is_some(), inner.status.state.clone())
        };
        if !linked {
            break;
        }
        if !matches!(state.as_str(), "Connecting" | "Disconnected") {
            answered = true;
            break;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    if !answered {
        disconnect_now(&app.hub, "no status report");
        return Err(Bad {
            status: 502,
            message: format!(
                "{port}: no answer to a status request (?): is it a Grbl machine at 115200 baud?"
            ),
        });
    }
    // Its figures, for the ETA and the settings table; a machine homing
    // at power-on reads the line once it is done.
    let _ = app.hub.console("$$", Duration::from_secs(30)).await;
    Ok(app.hub.snapshot())
}

fn disconnect_now(hub: &Hub, why: &str) {
    let mut inner = hub.lock();
    if let Some(link) = inner.link.take() {
        link.close();
        inner.status.state = "Disconnected".into();
        if let Some(run) = inner.run.as_mut().filter(|r| r.active()) {
            run.interrupt(why);
            hub.emit("run", run.report());
        }
        hub.log(
            &mut inner,
            "note",
            &format!("disconnected from {}", link.name),
        );
        hub.emit("link", json!({ "connected": false, "port": Value::Null }));
        hub.emit("status", json!({ "status": inner.status }));
    }
}

async fn disconnect(State(app): State<App>, headers: HeaderMap, uri: axum::http::Uri) -> Answer {
    control(&app, &client(&headers, &uri))?;
    disconnect_now(&app.hub, "disconnected");
    Ok(Json(json!({ "connected": false })))
}

async fn machine(State(app): State<App>) -> Json<Value> {
    let mut s = app.hub.snapshot();
    s["simulator"] = json!(app.sim.as_ref().map(|s| s.machine.name().to_string()));
    Json(s)
}

/// `POST /api/machine/line`: one console line (the body); its replies.
async fn line(
    State(app): State<App>,
    headers: HeaderMap,
    uri: axum::http::Uri,
    body: Body,
) -> Answer {
    control(&app, &client(&headers, &uri))?;
    let bytes = upload(&headers, body).await?;
    let text = String::from_utf8_lossy(&bytes);
    let line = text.trim_end_matches(['\r', '\n']);
    if line.contains(['\n', '\r']) {
        return Err(Bad::input("one line at a time".into()));
    }
    if line.len() > 127 {
        return Err(Bad::input(format!(
            "{} characters: Grbl's buffer takes 127",
            line.len()
        )));
    }
    // Homing and waiting for motion take as long as the machine needs.
    let upper = line.to_ascii_uppercase();
    let wait = match upper.as_str() {
        "$H" | "G28" | "M400" => Duration::from_secs(300),
        _ => Duration::from_secs(30),
    };
    let replies = app.hub.console(line, wait).await.map_err(Bad::conflict)?;
    let words: Vec<String> = replies
        .iter()
        .filter_map(|r| super::words::explain(r))
        .collect();
    Ok(Json(
        json!({ "line": line, "replies": replies, "words": words }),
    ))
}

/// `POST /api/machine/realtime?cmd=…`: one of Grbl's real-time bytes.
async fn realtime(State(app): State<App>, headers: HeaderMap, uri: axum::http::Uri) -> Answer {
    control(&app, &client(&headers, &uri))?;
    let q = options(&uri);
    let cmd = q.0.get("cmd").map(String::as_str).unwrap_or("");
    let byte = match cmd {
        "status" => b'?',
        "hold" => b'!',
        "resume" => b'~',
        "reset" => 0x18,
        "jog_cancel" => 0x85,
        _ => {
            return Err(Bad::input(format!(
                "cmd={cmd}: status, hold, resume, reset or jog_cancel"
            )))
        }
    };
    let mut inner = app.hub.lock();
    app.hub.write(&mut inner, &[byte]).map_err(Bad::conflict)?;
    let shown = match byte {
        0x18 => "^X (reset)".to_string(),
        0x85 => "0x85 (jog cancel)".to_string(),
        b => (b as char).to_string(),
    };
    if byte != b'?' {
        app.hub.log(&mut inner, "tx", &shown);
    }
    Ok(Json(json!({ "sent": shown })))
}

/// `POST /api/machine/button?name=green|zero_base|zero_radial|zero_drill
/// [&long=1]`: the simulated machine's button pressed; on a real machine
/// what the console can do instead (`~` resumes a paused job), or why not.
async fn button(State(app): State<App>, headers: HeaderMap, uri: axum::http::Uri) -> Answer {
    control(&app, &client(&headers, &uri))?;
    let q = options(&uri);
    let name = q.0.get("name").cloned().unwrap_or_default();
    let long = q.0.get("long").is_some_and(|v| v == "1" || v == "true");
    let b = Button::ALL
        .into_iter()
        .find(|b| b.name() == name || (name == "green" && *b == Button::Confirm))
        .ok_or_else(|| {
            Bad::input(format!(
                "name={name}: green, zero_base, zero_radial or zero_drill"
            ))
        })?;
    if let Some(sim) = &app.sim {
        sim.press(b, long).map_err(Bad::conflict)?;
        let mut inner = app.hub.lock();
        let what = format!(
            "{} button pressed{} (simulator)",
            name,
            if long { " for 2.5 s" } else { "" }
        );
        app.hub.log(&mut inner, "note", &what);
        return Ok(Json(json!({ "pressed": name, "long": long })));
    }
    let paused = app.hub.lock().job.state.as_deref() == Some("paused");
    if b == Button::Confirm && !long && paused {
        let mut inner = app.hub.lock();
        app.hub.write(&mut inner, b"~").map_err(Bad::conflict)?;
        app.hub.log(&mut inner, "tx", "~");
        return Ok(Json(json!({ "sent": "~" })));
    }
    Err(Bad::conflict(
        "press it on the machine: the firmware takes this button from its pin only (the console's ~ resumes a paused job)",
    ))
}

/// `POST /api/sim/card`: the card (`poradi.txt` the body, the board the
/// query) put in the simulated machine's slot.
async fn sim_card(
    State(app): State<App>,
    headers: HeaderMap,
    uri: axum::http::Uri,
    body: Body,
) -> Answer {
    control(&app, &client(&headers, &uri))?;
    let sim = app.sim.as_ref().ok_or_else(|| {
        Bad::conflict("no simulator: start taut studio with --sim (cargo xtask studio)")
    })?;
    let bytes = upload(&headers, body).await?;
    let (spec, pattern) = tools::card_files(&bytes, &options(&uri))?;
    let param = spec.param_txt();
    sim.insert_card(&[("param.txt", param.as_bytes()), ("poradi.txt", &bytes[..])])
        .map_err(Bad::conflict)?;
    let mut inner = app.hub.lock();
    let note = format!(
        "card put in the simulator: {} nails, {} connections",
        spec.nails,
        pattern.len()
    );
    app.hub.log(&mut inner, "note", &note);
    Ok(Json(
        json!({ "inserted": true, "nails": spec.nails, "connections": pattern.len() }),
    ))
}

/// `POST /api/sim/power_cut`: the simulated machine's power cut and
/// switched on again at once. Only its EEPROM (a byte being written left
/// erased) and the card in its slot survive: a string-art job offers to
/// resume from its checkpoint; a G-code run is over (the board reset).
async fn power_cut(State(app): State<App>, headers: HeaderMap, uri: axum::http::Uri) -> Answer {
    control(&app, &client(&headers, &uri))?;
    let sim = app.sim.clone().ok_or_else(|| {
        Bad::conflict("no simulator: start taut studio with --sim (cargo xtask studio)")
    })?;
    {
        let mut inner = app.hub.lock();
        let note =
            "power cut (simulator): the machine keeps its EEPROM and its card, and starts again";
        app.hub.log(&mut inner, "note", note);
    }
    let cuts = blocking(move || sim.power_cut().map_err(Bad::conflict)).await?;
    Ok(Json(json!({ "power_cuts": cuts })))
}

/// `POST /api/run?name=…`: the body, a G-code file, checked as the
/// machine reads it, then streamed.
async fn run_start(
    State(app): State<App>,
    headers: HeaderMap,
    uri: axum::http::Uri,
    body: Body,
) -> Answer {
    control(&app, &client(&headers, &uri))?;
    let bytes = upload(&headers, body).await?;
    let q = options(&uri);
    let name = q.0.get("name").cloned().unwrap_or_else(|| "G-code".into());
    let (settings, connected) = {
        let inner = app.hub.lock();
        (inner.settings.clone(), inner.link.is_some())
    };
    if !connected {
        return Err(Bad::conflict("not connected: connect to the machine first"));
    }
    // The machine's own figures (its `$$`), or its defaults.
    let (machine, config) = match crate::send::config_of(&settings) {
        Some((_, cfg)) => (cfg.machine, cfg),
        None => (app.machine, MachineConfig::defaults(app.machine)),
    };
    let check = bytes.clone();
    blocking(move || check_gcode(&check, machine)).await?;
    let mut run = Run::new(&name, &bytes, &config).map_err(Bad::input)?;
    let mut inner = app.hub.lock();
    let inner = &mut *inner;
    if inner.run.as_ref().is_some_and(Run::active) {
        return Err(Bad::conflict("a run is going: stop it first"));
    }
    if inner.link.is_none() {
        return Err(Bad::conflict("not connected"));
    }
    let mut out = Vec::new();
    run.fill(&mut out).map_err(Bad::input)?;
    let report = run.report();
    inner.run = Some(run);
    app.hub.log(inner, "note", &format!("run {name}: started"));
    for sent in out {
        let text = String::from_utf8_lossy(&sent).trim_end().to_string();
        app.hub.write(inner, &sent).map_err(Bad::conflict)?;
        app.hub.log(inner, "tx", &text);
    }
    app.hub.emit("run", report.clone());
    Ok(Json(report))
}

/// The file read as the machine reads it: the first line it would refuse,
/// with where and why, refuses the run before anything is sent. Lines no
/// preview can follow (`$` settings, homing) are the machine's to judge.
fn check_gcode(bytes: &[u8], machine: taut_logic::machine::Machine) -> Result<(), Bad> {
    let text = std::str::from_utf8(bytes)
        .map_err(|e| Bad::input(format!("not a text file (byte {})", e.valid_up_to() + 1)))?;
    match crate::toolpath::from_gcode(text, machine) {
        Ok(_) => Ok(()),
        Err(e) if e.contains("$ or card command") || e.contains("homing (G28)") => Ok(()),
        Err(e) => Err(Bad::input(format!(
            "the G-code, {e}: nothing was sent to the {}",
            machine.name()
        ))),
    }
}

async fn run_report(State(app): State<App>) -> Json<Value> {
    Json(match &app.hub.lock().run {
        Some(run) => run.report(),
        None => json!({ "state": "idle", "line": 0, "of": 0 }),
    })
}

/// `POST /api/run/pause|resume|stop`: `!`, `~`, Ctrl-X.
async fn run_action(
    State(app): State<App>,
    Path(action): Path<String>,
    headers: HeaderMap,
    uri: axum::http::Uri,
) -> Answer {
    control(&app, &client(&headers, &uri))?;
    let mut inner = app.hub.lock();
    let inner = &mut *inner;
    let run = inner
        .run
        .as_mut()
        .filter(|r| r.active())
        .ok_or_else(|| Bad::conflict("no run is going"))?;
    let byte = match action.as_str() {
        "pause" => {
            run.hold(true).map_err(Bad::conflict)?;
            b'!'
        }
        "resume" => {
            run.hold(false).map_err(Bad::conflict)?;
            b'~'
        }
        "stop" => {
            run.interrupt("stopped: Ctrl-X sent, the machine reset");
            0x18
        }
        a => {
            return Err(Bad {
                status: 404,
                message: format!("/api/run/{a}: pause, resume or stop"),
            })
        }
    };
    let report = run.report();
    app.hub.write(inner, &[byte]).map_err(Bad::conflict)?;
    let shown = match byte {
        0x18 => "^X (reset)".to_string(),
        b => (b as char).to_string(),
    };
    app.hub.log(inner, "tx", &shown);
    app.hub.emit("run", report.clone());
    Ok(Json(report))
}

/// `GET /api/events?client=ID`: a WebSocket of JSON events: first
/// `hello` (the whole state), then `status`, `log`, `run`, `job`,
/// `link`, `controller` as they happen.
async fn events(
    State(app): State<App>,
    headers: HeaderMap,
    uri: axum::http::Uri,
    ws: WebSocketUpgrade,
) -> Response {
    let who = client(&headers, &uri);
    ws.on_upgrade(move |socket| watch(app, who, socket))
}

async fn watch(app: App, who: String, mut socket: WebSocket) {
    let mut events = app.hub.subscribe();
    let hello = {
        let mut inner = app.hub.lock();
        inner.watchers.push(who.clone());
        // The first page to open controls the machine.
        if inner.controller.is_none() {
            inner.controller = Some(who.clone());
            app.hub.emit("controller", json!({ "controller": who }));
        }
        drop(inner);
        let mut s = app.hub.snapshot();
        s["type"] = json!("hello");
        s["you"] = json!(who);
        s["simulator"] = json!(app.sim.as_ref().map(|s| s.machine.name().to_string()));
        s
    };
    if socket
        .send(Message::Text(hello.to_string().into()))
        .await
        .is_err()
    {
        return left(&app, &who);
    }
    loop {
        tokio::select! {
            e = events.recv() => match e {
                Ok(text) => {
                    if socket.send(Message::Text(text.into())).await.is_err() {
                        break;
                    }
                }
                Err(tokio::sync::broadcast::error::RecvError::Lagged(_)) => {
                    let mut s = app.hub.snapshot();
                    s["type"] = json!("hello");
                    s["you"] = json!(who);
                    if socket.send(Message::Text(s.to_string().into())).await.is_err() {
                        break;
                    }
                }
                Err(_) => break,
            },
            m = socket.recv() => match m {
                Some(Ok(Message::Close(_))) | None | Some(Err(_)) => break,
                _ => {}
            },
        }
    }
    left(&app, &who);
}

/// A page closed: a controller with no page left hands control back.
fn left(app: &Studio, who: &str) {
    let mut inner = app.hub.lock();
    if let Some(i) = inner.watchers.iter().position(|w| w == who) {
        inner.watchers.remove(i);
    }
    if inner.controller.as_deref() == Some(who) && !inner.watchers.iter().any(|w| w == who) {
        inner.controller = None;
        app.hub
            .emit("controller", json!({ "controller": Value::Null }));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn query_strings_decode_and_tokens_compare_whole() {
        let uri: axum::http::Uri = "/api/text?a=1&text=Hello%2C+world%21&at=3%2C4&b"
            .parse()
            .unwrap();
        let q = query_pairs(&uri);
        assert_eq!(q["text"], "Hello, world!");
        assert_eq!(q["at"], "3,4");
        assert_eq!(q["b"], "");
        assert!(same(b"abc", b"abc") && !same(b"abc", b"abd") && !same(b"ab", b"abc"));
    }
}
