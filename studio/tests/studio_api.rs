//! `taut studio`'s HTTP API without a machine: every endpoint's answer,
//! the token rule, the one-controller rule, and bad input refused with
//! what is wrong while the server goes on. (With the machine, the
//! simulated Mega: `hil-tests/tests/hil/studio_app.rs`; in a browser:
//! `hil-tests/tests/hil/studio_browser.rs`.)

use axum::body::Body;
use axum::http::{Request, StatusCode};
use base64::Engine;
use http_body_util::BodyExt;
use serde_json::Value;
use std::net::{IpAddr, Ipv4Addr};
use std::path::Path;
use taut_studio::app::{self, Options};
use tower::ServiceExt;

fn example(name: &str) -> Vec<u8> {
    std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../examples/images")
            .join(name),
    )
    .unwrap()
}

async fn studio(token: Option<&str>) -> axum::Router {
    let o = Options {
        port: 0,
        token: token.map(str::to_string),
        ..Options::default()
    };
    app::start(o).await.unwrap().router()
}

struct Reply {
    status: StatusCode,
    headers: axum::http::HeaderMap,
    body: Vec<u8>,
}

impl Reply {
    fn json(&self) -> Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|_| panic!("not JSON: {}", String::from_utf8_lossy(&self.body)))
    }

    fn error(&self) -> String {
        self.json()["error"]
            .as_str()
            .unwrap_or_default()
            .to_string()
    }
}

async fn call(
    app: &axum::Router,
    method: &str,
    uri: &str,
    body: Vec<u8>,
    headers: &[(&str, &str)],
) -> Reply {
    let mut req = Request::builder().method(method).uri(uri);
    for (k, v) in headers {
        req = req.header(*k, *v);
    }
    let res = app
        .clone()
        .oneshot(req.body(Body::from(body)).unwrap())
        .await
        .unwrap();
    let status = res.status();
    let headers = res.headers().clone();
    let body = res.into_body().collect().await.unwrap().to_bytes().to_vec();
    Reply {
        status,
        headers,
        body,
    }
}

async fn get(app: &axum::Router, uri: &str) -> Reply {
    call(app, "GET", uri, Vec::new(), &[]).await
}

async fn post(app: &axum::Router, uri: &str, body: impl Into<Vec<u8>>) -> Reply {
    call(app, "POST", uri, body.into(), &[]).await
}

/// A POST that must succeed: its JSON.
async fn posted(app: &axum::Router, uri: &str, body: impl Into<Vec<u8>>) -> Value {
    let r = post(app, uri, body).await;
    assert_eq!(r.status, 200, "{uri}: {}", r.error());
    r.json()
}

/// A request that must be refused with `status` and an error holding
/// `want`.
async fn refused(reply: Reply, what: &str, status: u16, want: &str) {
    assert_eq!(reply.status.as_u16(), status, "{what}: {}", reply.error());
    assert!(
        reply.error().contains(want),
        "{what}: {:?} lacks {want:?}",
        reply.error()
    );
}

fn example_svg(name: &str) -> Vec<u8> {
    std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../examples/svg")
            .join(name),
    )
    .unwrap()
}

fn png(b64: &Value) -> Vec<u8> {
    base64::engine::general_purpose::STANDARD
        .decode(b64.as_str().unwrap())
        .unwrap()
}

#[tokio::test]
async fn the_page_and_its_files_are_served_from_the_binary() {
    let app = studio(None).await;
    let page = get(&app, "/").await;
    assert_eq!(page.status, 200);
    let html = String::from_utf8(page.body).unwrap();
    for id in [
        "open",
        "vectorize",
        "stringart",
        "connect",
        "console-input",
        "send",
        "pause",
        "resume",
        "stop",
        "progress",
        "position",
    ] {
        assert!(html.contains(&format!("data-testid=\"{id}\"")), "no {id}");
    }
    assert!(get(&app, "/app.js")
        .await
        .body
        .starts_with(b"// taut studio"));
    assert_eq!(get(&app, "/style.css").await.status, 200);
    let missing = get(&app, "/nothing").await;
    assert_eq!(
        (missing.status, missing.error().as_str()),
        (StatusCode::NOT_FOUND, "no such page or API")
    );
    let machines = get(&app, "/api/machines").await.json();
    assert_eq!(machines.as_array().unwrap().len(), 5);
    assert_eq!(machines[2]["name"], "flatbed");
    assert_eq!(machines[2]["width_max_mm"], 140.0);
    assert!(get(&app, "/api/ports").await.json().is_array());
}

#[tokio::test]
async fn a_picture_is_vectorised_with_its_time_travel_and_preview() {
    let app = studio(None).await;
    let v = posted(
        &app,
        "/api/vectorize?machine=flatbed&width_mm=30&canny=60,160",
        example("horse.png"),
    )
    .await;
    let gcode = v["gcode"].as_str().unwrap();
    assert!(gcode.contains("G1 X") && v["lines"].as_u64().unwrap() > 20);
    assert!(v["estimate_s"].as_f64().unwrap() > 1.0);
    assert!(v["pen_up_mm"].as_f64().unwrap() > 0.0 && v["pen_down_mm"].as_f64().unwrap() > 30.0);
    assert!(png(&v["preview_png"]).starts_with(b"\x89PNG"));
    let moves = v["toolpath"].as_array().unwrap();
    assert!(moves.iter().any(|m| m[4] == 1) && moves.iter().any(|m| m[4] == 0));
    // Kept within the flatbed's 140 mm.
    let wide = posted(
        &app,
        "/api/vectorize?machine=flatbed&width_mm=500",
        example("horse.png"),
    )
    .await;
    assert_eq!(wide["width_mm"], 140.0);
    assert!(wide["note"]
        .as_str()
        .unwrap()
        .contains("kept within the flatbed's travel: 140 mm"));
    // Hatching, on another machine.
    posted(
        &app,
        "/api/vectorize?machine=drum&width_mm=40&mode=hatch&hatch_mm=2",
        example("horse.png"),
    )
    .await;
}

#[tokio::test]
async fn an_svg_is_drawn_from_its_shapes_at_its_own_size_or_scaled() {
    let app = studio(None).await;
    // Inkscape's layers: one pass each (the hidden one left out), at the
    // page's own 120 mm.
    let v = posted(
        &app,
        "/api/vectorize?machine=flatbed&mode=edges",
        example_svg("inkscape-layers.svg"),
    )
    .await;
    assert_eq!(
        (v["svg"].clone(), v["layers"].clone()),
        (true.into(), 3.into()),
        "{}",
        v["note"]
    );
    let own = v["width_mm"].as_f64().unwrap();
    assert!((own - 120.0).abs() < 0.01, "{own}");
    assert!(v["gcode"]
        .as_str()
        .unwrap()
        .contains("M0 (MSG, change the pen: pass 2 of 3"));
    let moves = v["toolpath"].as_array().unwrap();
    assert!(moves.iter().any(|m| m[4] == 1) && v["estimate_s"].as_f64().unwrap() > 1.0);
    // Scaled, in one pass.
    let half = posted(
        &app,
        "/api/vectorize?machine=flatbed&width_mm=60&one_pen=1",
        example_svg("inkscape-layers.svg"),
    )
    .await;
    assert_eq!(
        (half["width_mm"].clone(), half["layers"].clone()),
        (60.0.into(), 1.into())
    );
    // The ink's box scales with the page (the hatching's spacing does not).
    let wide =
        |v: &Value| v["bounds"][1][0].as_f64().unwrap() - v["bounds"][0][0].as_f64().unwrap();
    let (a, b) = (wide(&v), wide(&half));
    assert!(
        (a / b - 2.0).abs() < 0.02,
        "the ink {a} mm wide at 120 mm, {b} at 60"
    );
    // Text not converted to paths is left out, and said so.
    let t = posted(
        &app,
        "/api/vectorize?machine=flatbed",
        &b"<svg xmlns='http://www.w3.org/2000/svg' width='40mm' height='20mm' viewBox='0 0 40 20'>\
           <rect x='5' y='5' width='30' height='10' fill='none' stroke='black'/>\
           <text x='8' y='12'>hi</text></svg>"[..],
    )
    .await;
    assert!(
        t["note"]
            .as_str()
            .unwrap()
            .starts_with("1 text element(s) not drawn"),
        "{}",
        t["note"]
    );
}

#[tokio::test]
async fn broken_pictures_and_options_are_refused_with_what_is_wrong() {
    let app = studio(None).await;
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        (
            "/api/vectorize",
            Vec::new(),
            "no picture: the body is empty",
        ),
        (
            "/api/vectorize",
            b"hello".to_vec(),
            "the picture: not a PNG or JPEG image",
        ),
        (
            "/api/vectorize",
            example("horse.png")[..400].to_vec(),
            "the picture: ",
        ),
        (
            "/api/vectorize",
            b"<svg xmlns='http://www.w3.org/2000/svg'>\n<path d='M0 0 L5 5'></svg>".to_vec(),
            "SVG: expected 'path' tag, not 'svg' at 2:",
        ),
        (
            "/api/vectorize",
            b"<svg xmlns='http://www.w3.org/2000/svg' width='10mm' height='10mm'/>".to_vec(),
            "nothing to draw: the SVG has no visible shapes",
        ),
        (
            "/api/vectorize?width_mm=abc",
            example("horse.png"),
            "width_mm=abc: not a number",
        ),
        (
            "/api/vectorize?machine=string_art",
            example("horse.png"),
            "--machine string_art: flatbed, drum, whiteboard or scara",
        ),
        (
            "/api/vectorize?mode=dots",
            example("horse.png"),
            "mode=dots: edges, hatch, outline, centerline or auto",
        ),
        (
            "/api/vectorize?canny=1",
            example("horse.png"),
            "canny=1: expected two numbers, X,Y",
        ),
        (
            "/api/text",
            "中".as_bytes().to_vec(),
            "no glyph for '中' (U+4E2D)",
        ),
        (
            "/api/text?font=comic",
            b"hi".to_vec(),
            "--font comic: one of",
        ),
        (
            "/api/gcode",
            b"G21\nG0 X10\nG0 X150\n".to_vec(),
            "the G-code, line 3: error:15 Travel exceeded",
        ),
        (
            "/api/gcode",
            b"G21\nG1 X10 Q\n".to_vec(),
            "the G-code, line 2: error:",
        ),
        (
            "/api/gcode",
            vec![0xff, 0xfe, 0],
            "not a text file (byte 1)",
        ),
        ("/api/stringart?nails=2", example("horse.png"), "param.txt"),
        (
            "/api/stringart?radius_cm=-1",
            example("horse.png"),
            "radius_cm must be above 0",
        ),
        (
            "/api/card?nails=24&shape=6&radius_cm=10&dir=/tmp/x",
            b"3\n0,1,99\n".to_vec(),
            "poradi.txt",
        ),
    ];
    for (uri, body, want) in cases {
        refused(post(&app, uri, body).await, uri, 400, want).await;
    }
    // Too big: refused by its declared length and by what came.
    let big = vec![b'x'; app::UPLOAD_LIMIT + 1];
    let r = post(&app, "/api/vectorize", big.clone()).await;
    refused(
        r,
        "too big",
        413,
        "the file is over 25 MB, the most the studio takes",
    )
    .await;
    let length = (big.len() + (1 << 20)).to_string();
    let header = [("content-length", length.as_str())];
    let r = call(&app, "POST", "/api/stringart", big, &header).await;
    let said = "the file is 26.0 MB: the studio takes files up to 25 MB";
    refused(r, "declared too big", 413, said).await;
    // The server goes on.
    posted(&app, "/api/text?height_mm=5", &b"ok"[..]).await;
}

#[tokio::test]
async fn text_gcode_and_string_art_come_back_with_their_figures() {
    let app = studio(None).await;
    let t = posted(
        &app,
        "/api/text?height_mm=8&font=scripts&machine=scara",
        &b"Hi"[..],
    )
    .await;
    assert!(t["estimate_s"].as_f64().unwrap() > 0.0);
    let g = posted(
        &app,
        "/api/gcode?machine=flatbed",
        &b"G21\nG90\nM5\nG0 X10 Y10\nM3\nG1 X20 F600\nM5\n"[..],
    )
    .await;
    assert_eq!(g["pen_down_mm"], 10.0);
    let s = posted(
        &app,
        "/api/stringart?nails=24&shape=6&radius_cm=10&lines=40&resolution=64&zoom=1.5&contrast=1.4",
        example("horse.png"),
    )
    .await;
    assert_eq!(
        s["param"],
        "tvar = 6\npocet_hrebiku = 24\npolomer_matrice = 10\n"
    );
    assert!(s["poradi"].as_str().unwrap().starts_with("40,\n"));
    assert!(s["estimate_s"].as_f64().unwrap() > 60.0 && s["thread_m"].as_f64().unwrap() > 1.0);
    assert!(
        png(&s["preview_png"]).starts_with(b"\x89PNG")
            && png(&s["framed_png"]).starts_with(b"\x89PNG")
    );
    // The card, written into a folder, as the firmware's parsers read it.
    let dir = std::env::temp_dir().join(format!("taut-studio-api-card-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let uri = format!(
        "/api/card?nails=24&shape=6&radius_cm=10&dir={}",
        dir.display()
    );
    posted(&app, &uri, s["poradi"].as_str().unwrap()).await;
    assert_eq!(
        std::fs::read_to_string(dir.join("poradi.txt")).unwrap(),
        s["poradi"].as_str().unwrap()
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("param.txt")).unwrap(),
        s["param"].as_str().unwrap()
    );
    assert!(dir.join("preview.png").exists());
    std::fs::remove_dir_all(&dir).unwrap();
    let t = get(&app, "/api/template?nails=24&shape=6&radius_cm=10").await;
    assert_eq!(t.status, 200);
    assert_eq!(t.headers["content-type"], "image/svg+xml");
    assert!(String::from_utf8(t.body).unwrap().contains("24 nails"));
}

#[tokio::test]
async fn without_a_machine_the_machine_endpoints_say_so_and_send_nothing() {
    let app = studio(None).await;
    let m = get(&app, "/api/machine").await.json();
    assert_eq!(
        (m["connected"].clone(), m["status"]["state"].clone()),
        (false.into(), "Disconnected".into())
    );
    assert_eq!(get(&app, "/api/run").await.json()["state"], "idle");
    for (uri, body, status, want) in [
        ("/api/machine/line", "$$", 409, "not connected"),
        ("/api/machine/realtime?cmd=hold", "", 409, "not connected"),
        (
            "/api/machine/realtime?cmd=fly",
            "",
            400,
            "cmd=fly: status, hold, resume, reset or jog_cancel",
        ),
        (
            "/api/run",
            "G0 X1\n",
            409,
            "not connected: connect to the machine first",
        ),
        ("/api/run/pause", "", 409, "no run is going"),
        ("/api/run/stop", "", 409, "no run is going"),
        (
            "/api/machine/button?name=green",
            "",
            409,
            "press it on the machine",
        ),
        (
            "/api/machine/button?name=red",
            "",
            400,
            "name=red: green, zero_base, zero_radial or zero_drill",
        ),
        ("/api/sim/card?nails=24", "1\n3\n", 409, "no simulator"),
        ("/api/sim/power_cut", "", 409, "no simulator"),
        (
            "/api/connect?port=/nonexistent/tty",
            "",
            502,
            "/nonexistent/tty: ",
        ),
        ("/api/connect", "", 400, "missing port"),
    ] {
        refused(post(&app, uri, body).await, uri, status, want).await;
    }
    let r = post(&app, "/api/disconnect", Vec::new()).await;
    assert_eq!(r.json()["connected"], false);
}

#[tokio::test]
async fn with_a_token_every_request_needs_it() {
    let app = studio(Some("s3cret-token")).await;
    let with = |uri: &'static str, header: (&'static str, &'static str)| {
        let app = app.clone();
        async move { call(&app, "GET", uri, Vec::new(), &[header]).await }
    };
    for uri in ["/", "/app.js", "/api/machine", "/api/run"] {
        refused(get(&app, uri).await, uri, 401, "a token is needed").await;
    }
    let wrong = with("/api/machine", ("authorization", "Bearer s3cret-tokem")).await;
    refused(wrong, "a wrong token", 401, "a token is needed").await;
    let right = with("/api/machine", ("authorization", "Bearer s3cret-token")).await;
    assert_eq!(right.status, 200);
    // Opened with ?token=, the page gets a cookie its files and calls use.
    let page = get(&app, "/?token=s3cret-token").await;
    assert_eq!(page.status, 200);
    let cookie = page.headers["set-cookie"].to_str().unwrap().to_string();
    assert!(cookie.starts_with("taut_token=s3cret-token;") && cookie.contains("HttpOnly"));
    let js = with("/app.js", ("cookie", "taut_token=s3cret-token")).await;
    assert_eq!(js.status, 200);
    posted(&app, "/api/text?token=s3cret-token", &b"x"[..]).await;
    // A short token is refused; on 127.0.0.1 none is needed.
    let any = IpAddr::V4(Ipv4Addr::UNSPECIFIED);
    assert!(app::token_for(any, Some("short".into())).is_err());
    assert_eq!(
        app::token_for(IpAddr::V4(Ipv4Addr::LOCALHOST), None).unwrap(),
        None
    );
}

/// Bound beyond this computer without `--token`, the studio makes one up
/// and prints it in its address: without it, 401.
#[tokio::test]
async fn on_another_address_a_token_is_made_and_needed() {
    let o = Options {
        bind: IpAddr::V4(Ipv4Addr::UNSPECIFIED),
        port: 0,
        ..Options::default()
    };
    let started = app::start(o).await.unwrap();
    let token = started.url.split("?token=").nth(1).unwrap().to_string();
    assert_eq!(token.len(), 32, "{}", started.url);
    let app = started.router();
    for uri in ["/", "/api/machine", "/api/ports"] {
        refused(get(&app, uri).await, uri, 401, "a token is needed").await;
    }
    let page = get(&app, &format!("/?token={token}")).await;
    assert_eq!(page.status, 200);
    let auth = format!("Bearer {token}");
    let r = call(
        &app,
        "GET",
        "/api/run",
        Vec::new(),
        &[("authorization", &auth)],
    )
    .await;
    assert_eq!(r.json()["state"], "idle");
}

#[tokio::test]
async fn one_window_controls_the_machine_and_taking_over_is_explicit() {
    let app = studio(None).await;
    let a = [("x-taut-client", "tab-a")];
    let b = [("x-taut-client", "tab-b")];
    let watching = "another window controls the machine";
    // Tab A acts first: it controls (its connect fails: no such port).
    let r = call(
        &app,
        "POST",
        "/api/connect?port=/nonexistent",
        Vec::new(),
        &a,
    )
    .await;
    assert_eq!(r.status, 502);
    let who = get(&app, "/api/controller").await.json();
    assert_eq!(who["controller"], "tab-a");
    let r = call(
        &app,
        "POST",
        "/api/machine/realtime?cmd=hold",
        Vec::new(),
        &b,
    )
    .await;
    refused(r, "B acts", 409, watching).await;
    // B takes over; now A watches.
    let r = call(&app, "POST", "/api/controller", Vec::new(), &b).await;
    assert_eq!(r.json()["controller"], "tab-b");
    let r = call(&app, "POST", "/api/run/stop", Vec::new(), &a).await;
    refused(r, "A acts", 409, watching).await;
    // Watching needs no control.
    let r = call(&app, "GET", "/api/machine", Vec::new(), &a).await;
    assert_eq!(r.status, 200);
}

/// The binary: prints its URL, serves, and ends on SIGINT with status 0.
#[test]
fn taut_studio_prints_its_url_and_ends_on_ctrl_c() {
    use std::io::{BufRead, BufReader, Read, Write};
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_taut"))
        .args(["studio", "--port", "0"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let mut first = String::new();
    out.read_line(&mut first).unwrap();
    let url = first
        .trim()
        .strip_prefix("taut studio: ")
        .unwrap()
        .to_string();
    assert!(url.starts_with("http://127.0.0.1:"), "{first}");
    let addr = url.trim_start_matches("http://").trim_end_matches('/');
    let mut s = std::net::TcpStream::connect(addr).unwrap();
    s.write_all(b"GET /api/run HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")
        .unwrap();
    let mut answer = String::new();
    s.read_to_string(&mut answer).unwrap();
    assert!(
        answer.starts_with("HTTP/1.1 200") && answer.contains("\"idle\""),
        "{answer}"
    );
    let sent = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    let status = child.wait().unwrap();
    assert!(status.success(), "{status:?}");
}
