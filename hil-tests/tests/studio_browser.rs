//! `taut studio` clicked through in a real browser (Debian's Chromium,
//! headless, through chromedriver and fantoccini), against the release
//! image in simavr behind a pseudo-terminal, as `cargo xtask studio` runs:
//!
//! - a picture opened, vectorised, the simulated flatbed connected, the
//!   drawing sent, paused and resumed once: the drawing rebuilt from the
//!   trace's step and pen pulses lies on the toolpath the page showed,
//!   within a step of each motor;
//! - a string-art card generated in the page, put in the simulated
//!   string-art machine and run to its end from the page's job buttons:
//!   the nails wrapped, from the pulses, are the card's;
//! - `$X`, `$H`, a jog and `?` typed into the console, with their replies.
//!
//! No test may leave an error in the browser's log.

mod browser;

use browser::{Browser, Studio};
use std::path::Path;
use std::time::{Duration, Instant};
use taut_logic::config::MachineConfig;
use taut_logic::machine::Machine;
use taut_studio::vectorize::simplify::distance;

fn example(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/images")
        .join(name)
        .canonicalize()
        .unwrap()
        .display()
        .to_string()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_picture_is_vectorised_sent_paused_resumed_and_drawn_on_its_toolpath() {
    let wall = Instant::now();
    let mut studio = Studio::start(Machine::Flatbed, "plot").await;
    let mut b = Browser::open().await;
    b.client.goto(&studio.url).await.unwrap();
    b.until(
        "the page",
        Duration::from_secs(10),
        "return document.getElementById('ports').options.length > 0",
    )
    .await;

    // Open the picture: 30 mm wide, some twenty seconds of drawing.
    b.set("v-width", "30").await;
    b.set("v-feed", "1500").await;
    b.by_id("open")
        .await
        .send_keys(&example("horse.png"))
        .await
        .unwrap();
    b.click("vectorize").await;
    b.until("the toolpath", Duration::from_secs(30),
        "return S.drawing && S.drawing.width_mm === 30 && document.getElementById('v-figures').textContent.includes('G-code lines')").await;
    let figures = b.text("drawing-figures").await;
    assert!(
        figures.contains("drawing time") && figures.contains("pen-up travel"),
        "{figures}"
    );
    b.screenshot("vectorised.png").await;

    // Connect to the simulated flatbed (first in the port list).
    let port = b.js("return document.getElementById('ports').value").await;
    assert_eq!(port.as_str().unwrap(), studio.sim.tty.display().to_string());
    b.click("connect").await;
    b.until(
        "connected",
        Duration::from_secs(40),
        "return S.connected && S.settings.length > 0 && S.status.state === 'Idle'",
    )
    .await;

    // Send; pause once mid-run, resume.
    b.click("send").await;
    b.until(
        "running",
        Duration::from_secs(10),
        "return S.run && S.run.state === 'running' && S.run.line > 10",
    )
    .await;
    b.click("pause").await;
    b.until(
        "held",
        Duration::from_secs(10),
        "return S.status.state === 'Hold:0'",
    )
    .await;
    let held_at = b.js("return S.status.mpos").await;
    tokio::time::sleep(Duration::from_millis(800)).await;
    assert_eq!(
        b.js("return S.status.mpos").await,
        held_at,
        "moved while held"
    );
    let progress = b.text("progress").await;
    assert!(progress.starts_with("paused: line "), "{progress}");
    b.screenshot("paused.png").await;
    b.click("resume").await;
    b.until(
        "done",
        Duration::from_secs(120),
        "return S.run.state === 'done'",
    )
    .await;
    let progress = b.text("progress").await;
    assert!(progress.starts_with("done: "), "{progress}");
    let travelled = b.js("return S.travelled.length").await.as_u64().unwrap();
    assert!(
        travelled > 10,
        "{travelled} positions drawn over the preview"
    );
    assert!(b.text("position").await.starts_with("X "));
    let shot = b.screenshot("plotter.png").await;
    // The toolpath the page showed.
    let shown = b.js("return S.drawing.toolpath").await;
    b.assert_no_console_errors().await;
    b.close().await;

    // The drawing from the trace's pulses: every step with the pen down on
    // a pen-down move, up on a travel, within a step of each motor.
    let ended = studio.end().await;
    let text = std::fs::read_to_string(&studio.vcd).unwrap();
    let signals = taut_trace::vcd::parse(&text).unwrap();
    let cfg = MachineConfig::defaults(Machine::Flatbed);
    let points = taut_trace::picture::plot_points(&signals, &cfg, ended.origin).unwrap();
    let moves: Vec<([f64; 2], [f64; 2], bool)> = shown
        .as_array()
        .unwrap()
        .iter()
        .map(|m| {
            let f = |i: usize| m[i].as_f64().unwrap();
            ([f(0), f(1)], [f(2), f(3)], m[4] == 1)
        })
        .collect();
    let step = 1.0 / 40.0;
    let within = step * 2f64.sqrt() + 0.001;
    let (mut down, mut worst) = (0, 0.0f64);
    // From the pen's first stroke on: before it the machine homed at
    // power-on and went from where homing left it, which the toolpath
    // (read from the G-code alone) puts at 0, 0.
    let first = points
        .iter()
        .position(|(_, down)| *down)
        .expect("the pen went down");
    for ((x, y), is_down) in &points[first..] {
        let off = moves
            .iter()
            .filter(|m| m.2 == *is_down)
            .map(|m| distance([*x, *y], m.0, m.1))
            .fold(f64::MAX, f64::min);
        worst = worst.max(off);
        down += usize::from(*is_down);
        assert!(
            off <= within,
            "({x:.3}, {y:.3}) is {off:.3} mm off the toolpath, pen down: {is_down}"
        );
    }
    let drawn: f64 = moves
        .iter()
        .filter(|m| m.2)
        .map(|m| (m.1[0] - m.0[0]).hypot(m.1[1] - m.0[1]))
        .sum();
    assert!(
        down as f64 > 0.9 * drawn / step,
        "{down} steps down for {drawn:.1} mm"
    );
    eprintln!(
        "studio plot: {} steps ({down} pen down), worst {worst:.4} mm off; {:.0} s machine time; {} in {:.1} s",
        points.len() - first,
        ended.seconds,
        shot.display(),
        wall.elapsed().as_secs_f64()
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_string_art_card_made_in_the_page_is_wound_to_its_end() {
    let wall = Instant::now();
    let mut studio = Studio::start(Machine::StringArt, "card").await;
    let mut b = Browser::open().await;
    b.client.goto(&studio.url).await.unwrap();
    b.until(
        "the page",
        Duration::from_secs(10),
        "return document.getElementById('ports').options.length > 0",
    )
    .await;
    b.click("connect").await;
    b.until(
        "connected",
        Duration::from_secs(40),
        "return S.connected && S.settings.length > 0",
    )
    .await;
    // A quick machine: its axes 4 times as fast, accelerating 16 times as
    // hard (the steps, and so the replay, are the same), as a maker sets
    // them in the settings table.
    for axis in ["base", "radial", "drill"] {
        for (key, value) in [("max_rate", "8000"), ("accel", "8000")] {
            let line = format!("${axis}_{key}={value}");
            b.type_line("console-input", &line).await;
            let done = format!(
                "const l = [...document.querySelectorAll('#log div')].map(d => d.textContent); \
                 const i = l.lastIndexOf({line:?}); return i >= 0 && l.slice(i).includes('ok')"
            );
            b.until(&line, Duration::from_secs(10), &done).await;
        }
    }

    // A small board: 8 nails on a circle of 8 cm, 6 chords.
    b.js("document.getElementById('stringart-panel').open = true; document.getElementById('plotter-panel').open = false; return true").await;
    b.js("document.getElementById('s-live').checked = false; return true")
        .await;
    b.set("s-nails", "8").await;
    b.set("s-radius", "8").await;
    b.set("s-lines", "6").await;
    b.by_id("open")
        .await
        .send_keys(&example("horse.png"))
        .await
        .unwrap();
    b.click("stringart").await;
    b.until(
        "the card",
        Duration::from_secs(60),
        "return S.card && S.card.lines === 6 && document.getElementById('s-figures').textContent.includes('machine time')",
    )
    .await;
    let figures = b.text("card-figures").await;
    assert!(
        figures.contains("machine time") && figures.contains("thread"),
        "{figures}"
    );
    let poradi = b
        .js("return S.card.poradi")
        .await
        .as_str()
        .unwrap()
        .to_string();
    let pattern: Vec<u16> = poradi
        .lines()
        .skip(1)
        .flat_map(|l| l.split(','))
        .filter(|n| !n.trim().is_empty())
        .map(|n| n.trim().parse().unwrap())
        .collect();
    b.screenshot("stringart.png").await;
    b.click("card-insert").await;

    // The job: green at every prompt that asks for it, from the page.
    let limit = Instant::now() + Duration::from_secs(300);
    let mut presses = 0;
    loop {
        let prompt = b.js("return S.job && S.job.prompt").await;
        let prompt = prompt.as_str().unwrap_or("").to_string();
        if prompt.starts_with(">>> done") {
            break;
        }
        if prompt.contains("press green") {
            b.click("green").await;
            presses += 1;
            let before = prompt.clone();
            b.until(
                "the prompt answered",
                Duration::from_secs(20),
                &format!("return !S.job.prompt || S.job.prompt !== {before:?} || null"),
            )
            .await;
        }
        assert!(Instant::now() < limit, "the job did not end: {prompt}");
        tokio::time::sleep(Duration::from_millis(200)).await;
    }
    let count = b.text("job-count").await;
    assert_eq!(count, format!("wind {}/{}", pattern.len(), pattern.len()));
    b.screenshot("job-done.png").await;
    b.assert_no_console_errors().await;
    b.close().await;

    let ended = studio.end().await;
    let text = std::fs::read_to_string(&studio.vcd).unwrap();
    let signals = taut_trace::vcd::parse(&text).unwrap();
    let param = format!("tvar = 0\npocet_hrebiku = 8\npolomer_matrice = 8\n");
    let (_, wrapped) = taut_studio::preview::wrapped_nails(&signals, param.as_bytes()).unwrap();
    assert_eq!(wrapped, pattern, "the nails wrapped, from the pulses");
    eprintln!(
        "studio card {pattern:?}: {presses} presses of green, {:.0} s machine time in {:.1} s",
        ended.seconds,
        wall.elapsed().as_secs_f64()
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_console_answers_unlock_home_a_jog_and_a_status_request() {
    let mut studio = Studio::start(Machine::Flatbed, "console").await;
    let mut b = Browser::open().await;
    b.client.goto(&studio.url).await.unwrap();
    b.until(
        "the page",
        Duration::from_secs(10),
        "return document.getElementById('ports').options.length > 0",
    )
    .await;
    b.click("connect").await;
    b.until(
        "connected",
        Duration::from_secs(40),
        "return S.connected && S.settings.length > 0 && S.status.state === 'Idle'",
    )
    .await;
    // The console's lines after the n-th, as the page shows them.
    let lines_after = |n: usize| {
        format!("return [...document.querySelectorAll('#log div')].slice({n}).map(d => d.firstChild.textContent)")
    };
    let count = "return document.querySelectorAll('#log div').length";
    let mut answers = Vec::new();
    for (line, want) in [
        ("$X", "ok"),
        ("$H", "ok"),
        ("$J=G91 X5 Y2 F600", "ok"),
        ("?", "<"),
    ] {
        let n = b.js(count).await.as_u64().unwrap() as usize;
        b.type_line("console-input", line).await;
        let got = b
            .until(
                line,
                Duration::from_secs(60),
                &format!(
                    "const l = {}; return l.some(t => t.startsWith('{want}')) ? l : null",
                    lines_after(n).trim_start_matches("return ")
                ),
            )
            .await;
        let got: Vec<String> = got
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap().to_string())
            .collect();
        assert_eq!(got[0], line, "the line typed is shown first");
        answers.push(got);
    }
    // `$X` unlocks ([MSG:Caution: Unlocked] where it was locked), `$H`
    // homes, the jog moves 5 mm, `?` reports where it stands.
    assert_eq!(answers[0].last().unwrap(), "ok");
    assert_eq!(answers[1].last().unwrap(), "ok");
    let status = answers[3].iter().find(|l| l.starts_with('<')).unwrap();
    assert!(
        status.starts_with("<Idle|MPos:") || status.starts_with("<Jog|MPos:"),
        "{status}"
    );
    b.until(
        "the jog's end",
        Duration::from_secs(10),
        "return S.status.state === 'Idle'",
    )
    .await;
    let pos = b.js("return S.status.mpos").await;
    let y = pos[1].as_f64().unwrap();
    assert!((y - 2.0).abs() < 0.03, "Y {y} after a 2 mm jog");
    // A refused line in plain words, with what to do.
    b.type_line("console-input", "G1 X500 F100").await;
    let notice = b.until("the refusal", Duration::from_secs(10),
        "const n = document.getElementById('notice'); return !n.hidden && n.textContent.includes('error:15') ? n.textContent : null").await;
    assert!(notice.as_str().unwrap().contains("What to do:"), "{notice}");
    // The jog button: held jogs, released cancels (0x85).
    let x0 = b.js("return S.status.mpos[0]").await.as_f64().unwrap();
    b.js(
        "const e = document.querySelector('[data-testid=\"jog-x+\"]'); \
          e.dispatchEvent(new PointerEvent('pointerdown', {bubbles: true})); return true",
    )
    .await;
    b.until(
        "jogging",
        Duration::from_secs(10),
        &format!("return S.status.mpos[0] > {x0} + 0.01"),
    )
    .await;
    b.js(
        "const e = document.querySelector('[data-testid=\"jog-x+\"]'); \
          e.dispatchEvent(new PointerEvent('pointerup', {bubbles: true})); return true",
    )
    .await;
    b.until("jog cancel sent", Duration::from_secs(10),
        "return [...document.querySelectorAll('#log div')].some(d => d.textContent.startsWith('0x85'))").await;
    b.until(
        "standing",
        Duration::from_secs(10),
        "return S.status.state === 'Idle'",
    )
    .await;
    let x1 = b.js("return S.status.mpos[0]").await.as_f64().unwrap();
    assert!(x1 > x0 && x1 <= x0 + 1.0 + 0.03, "jogged from {x0} to {x1}");
    b.screenshot("console.png").await;
    b.assert_no_console_errors().await;
    b.close().await;
    studio.end().await;
}
