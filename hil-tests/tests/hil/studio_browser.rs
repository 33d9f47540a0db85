//! `taut studio` clicked through in a real browser (Debian's Chromium,
//! headless, through chromedriver and fantoccini), against the release
//! image in simavr behind a pseudo-terminal, as `cargo xtask studio` runs:
//!
//! - a picture opened, vectorised, the simulated flatbed connected, the
//!   drawing sent, paused and resumed once: the drawing rebuilt from the
//!   trace's step and pen pulses lies on the toolpath the page showed,
//!   within a step of each motor;
//! - a string-art card generated in the page, put in the simulated
//!   string-art machine and run from the page's job buttons; its power
//!   cut while winding, the resume offer taken and the axes zeroed from
//!   the page, and the job wound to its end: the nails wrapped, from the
//!   pulses of both power-ons, are the card's, none twice;
//! - `$X`, `$H`, a jog and `?` typed into the console, with their replies;
//!   a refused line in plain words; the buttons (unlock, home, jog held
//!   and released, pen, work zero, machine selection); a second window
//!   watching until it takes over; an SVG opened beside its toolpath.
//!
//! No test may leave an error in the browser's log.

mod browser;

use browser::{open_connected, Browser};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use taut_logic::config::MachineConfig;
use taut_logic::machine::Machine;
use taut_studio::vectorize::simplify::distance;

fn example(folder: &str, name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples")
        .join(folder)
        .join(name)
}

/// The console's lines as the page shows them (each line's own text).
const LOG: &str = "[...document.querySelectorAll('#log div')].map(d => d.firstChild.textContent)";

/// How many lines the console shows.
async fn logged(b: &Browser) -> usize {
    let n = b.js(&format!("return {LOG}.length")).await;
    n.as_u64().unwrap() as usize
}

/// Waits until the console shows, after its first `from` lines, `line`
/// sent and then a reply starting with `want`; returns the lines from
/// `line` on.
async fn answered(b: &Browser, from: usize, line: &str, want: &str) -> Vec<String> {
    let got = b
        .until(
            &format!("{line} answered"),
            Duration::from_secs(60),
            &format!(
                "const l = {LOG}.slice({from}); const i = l.indexOf({line:?}); \
                 return i >= 0 && l.slice(i + 1).some(t => t.startsWith({want:?})) ? l.slice(i) : null"
            ),
        )
        .await;
    got.as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap().to_string())
        .collect()
}

async fn idle(b: &Browser) {
    b.until(
        "Idle",
        Duration::from_secs(30),
        "return S.status.state === 'Idle'",
    )
    .await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_picture_is_vectorised_sent_paused_resumed_and_drawn_on_its_toolpath() {
    let wall = Instant::now();
    let (mut studio, mut b) = open_connected(Machine::Flatbed, "plot").await;
    idle(&b).await;

    // Open the picture: 30 mm wide, some twenty seconds of drawing.
    b.set("v-width", "30").await;
    b.set("v-feed", "1500").await;
    b.open_file(&example("images", "horse.png")).await;
    b.click_until("vectorize", "the toolpath", 30,
        "return S.drawing && S.drawing.width_mm === 30 && document.getElementById('v-figures').textContent.includes('G-code lines')").await;
    let figures = b.text("drawing-figures").await;
    assert!(
        figures.contains("drawing time") && figures.contains("pen-up travel"),
        "{figures}"
    );
    b.screenshot("vectorised.png").await;

    // Send; pause once mid-run, resume.
    b.click_until(
        "send",
        "running",
        10,
        "return S.run && S.run.state === 'running' && S.run.line > 10",
    )
    .await;
    let progress = b.text("progress").await;
    assert!(
        progress.starts_with("running: line ") && progress.contains(" %, ETA "),
        "{progress}"
    );
    b.click_until("pause", "held", 10, "return S.status.state === 'Hold:0'")
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
    b.click_until("resume", "done", 120, "return S.run.state === 'done'")
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

/// The nails wrapped in one power-on's trace.
fn wrapped(vcd: &Path, param: &str) -> Vec<u16> {
    let text = std::fs::read_to_string(vcd).unwrap();
    let signals = taut_trace::vcd::parse(&text).unwrap();
    taut_studio::preview::wrapped_nails(&signals, param.as_bytes())
        .unwrap()
        .1
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_string_art_card_made_in_the_page_survives_a_power_cut_and_is_wound_to_its_end() {
    let wall = Instant::now();
    let (mut studio, mut b) = open_connected(Machine::StringArt, "card").await;
    // A quick machine: its axes 4 times as fast, accelerating 16 times as
    // hard (the steps, and so the replay, are the same), set in the
    // settings table. The EEPROM keeps them through the power cut.
    for axis in ["base", "radial", "drill"] {
        for key in ["max_rate", "accel"] {
            b.edit_setting(&format!("{axis}_{key}"), "8000").await;
        }
    }

    // A small board: 8 nails on a circle of 8 cm, 6 chords.
    b.js("document.getElementById('stringart-panel').open = true; document.getElementById('plotter-panel').open = false; return true").await;
    b.js("document.getElementById('s-live').checked = false; return true")
        .await;
    b.set("s-nails", "8").await;
    b.set("s-radius", "8").await;
    b.set("s-lines", "6").await;
    b.open_file(&example("images", "horse.png")).await;
    b.click_until("stringart", "the card", 60, "return S.card && S.card.lines === 6 && document.getElementById('s-figures').textContent.includes('machine time')").await;
    let figures = b.text("card-figures").await;
    assert!(
        figures.contains("machine time") && figures.contains("thread"),
        "{figures}"
    );
    let poradi = b.js("return S.card.poradi").await;
    let pattern: Vec<u16> = poradi
        .as_str()
        .unwrap()
        .lines()
        .skip(1)
        .flat_map(|l| l.split(','))
        .filter(|n| !n.trim().is_empty())
        .map(|n| n.trim().parse().unwrap())
        .collect();
    b.screenshot("stringart.png").await;
    b.click("card-insert").await;

    // The job, from the page: green at every prompt that asks for it; the
    // power cut once two wraps are done; the resume offer taken, each
    // axis zeroed with its white button twice.
    let limit = Instant::now() + Duration::from_secs(300);
    let (mut presses, mut cut, mut offer) = (0, None, None);
    loop {
        let job = b.js("return S.job").await;
        let prompt = job["prompt"].as_str().unwrap_or("").to_string();
        let wound = match &job["progress"] {
            Value::Array(p) if p[0] == "wind" => p[1].as_u64().unwrap(),
            _ => 0,
        };
        if prompt.starts_with(">>> done") {
            break;
        }
        if cut.is_none() && job["state"] == "winding" && wound >= 2 {
            b.click("power-cut").await;
            cut = Some(wound);
            b.until(
                "the resume offer",
                Duration::from_secs(30),
                "return !document.getElementById('job-offer').hidden",
            )
            .await;
            offer = Some(b.text("job-checkpoint").await);
            b.screenshot("power-cut.png").await;
            b.click("job-resume").await;
        } else if prompt.starts_with(">>> axes were unpowered") {
            assert!(!b.text("job-hint").await.is_empty());
            for axis in ["zero-base", "zero-radial", "zero-drill"] {
                for _ in 0..2 {
                    b.click(axis).await;
                    tokio::time::sleep(Duration::from_millis(400)).await;
                }
            }
            b.click_until(
                "green",
                "the axes zeroed",
                20,
                &format!("return S.job.prompt !== {prompt:?} || null"),
            )
            .await;
        } else if prompt.contains("press green") {
            b.click("green").await;
            presses += 1;
            b.until(
                "the prompt answered",
                Duration::from_secs(20),
                &format!("return !S.job.prompt || S.job.prompt !== {prompt:?} || null"),
            )
            .await;
        }
        assert!(Instant::now() < limit, "the job did not end: {job}");
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    let count = b.text("job-count").await;
    assert_eq!(count, format!("wind {}/{}", pattern.len(), pattern.len()));
    let cut = cut.expect("the power was cut while winding");
    let offer = offer.unwrap();
    assert!(
        offer.starts_with("checkpoint: winding stopped at ") && offer.ends_with("power-on"),
        "{offer}"
    );
    b.screenshot("job-done.png").await;
    b.assert_no_console_errors().await;
    b.close().await;

    // The nails wrapped, from the pulses: before the cut a first part of
    // the card, after it the rest, none twice. A wrap whose needle went
    // out before the cut and came back in after it shows in neither
    // trace alone: at most one.
    let ended = studio.end().await;
    assert_eq!(ended.cut_traces.len(), 1);
    let param = "tvar = 0\npocet_hrebiku = 8\npolomer_matrice = 8\n";
    let before = wrapped(&ended.cut_traces[0], param);
    let after = wrapped(&studio.vcd, param);
    assert_eq!(before, pattern[..before.len()], "before the cut");
    assert_eq!(after, pattern[pattern.len() - after.len()..], "after it");
    let both = before.len() + after.len();
    assert!(
        both == pattern.len() || both + 1 == pattern.len(),
        "{before:?} then {after:?} of {pattern:?}"
    );
    assert!(before.len() as u64 >= cut.min(pattern.len() as u64) - 1);
    eprintln!(
        "studio card {pattern:?}: {before:?} | cut at wind {cut} | {after:?}; {presses} presses of green, \
         {:.0} s machine time in {:.1} s",
        ended.seconds,
        wall.elapsed().as_secs_f64()
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_console_and_buttons_answer_a_second_window_watches_and_an_svg_opens() {
    let (mut studio, mut b) = open_connected(Machine::Flatbed, "console").await;
    idle(&b).await;
    // The buttons send what a Grbl user expects; typed into the console,
    // `$X` unlocks ([MSG:Caution: Unlocked] where it was locked), `$H`
    // homes, the jog moves, `?` reports where it stands: each line shown
    // first, its replies after.
    for (how, line, want) in [
        ("unlock", "$X", "ok"),
        ("home", "$H", "ok"),
        ("pen-down", "M3", "ok"),
        ("pen-up", "M5", "ok"),
        ("type", "$X", "ok"),
        ("type", "$H", "ok"),
        ("type", "$J=G91 X5 Y2 F600", "ok"),
        ("type", "?", "<"),
    ] {
        let from = logged(&b).await;
        match how {
            "type" => b.type_line("console-input", line).await,
            button => b.click(button).await,
        }
        let got = answered(&b, from, line, want).await;
        if want == "<" {
            let status = got.iter().find(|l| l.starts_with('<')).unwrap();
            assert!(
                status.starts_with("<Idle|MPos:") || status.starts_with("<Jog|MPos:"),
                "{status}"
            );
        }
    }
    idle(&b).await;
    let pos = b.js("return S.status.mpos").await;
    let y = pos[1].as_f64().unwrap();
    assert!((y - 2.0).abs() < 0.03, "Y {y} after a 2 mm jog");
    // A refused line in plain words, with what to do.
    b.type_line("console-input", "G1 X500 F100").await;
    let notice = b.until("the refusal", Duration::from_secs(10),
        "const n = document.getElementById('notice'); return !n.hidden && n.textContent.includes('error:15') ? n.textContent : null").await;
    assert!(notice.as_str().unwrap().contains("What to do:"), "{notice}");
    // Work zero: G10 L20 as CNCjs sends it, or G92 where it is refused.
    let from = logged(&b).await;
    b.click("zero").await;
    let zero = b
        .until(
            "work zero",
            Duration::from_secs(10),
            &format!(
                "const l = {LOG}.slice({from}); const g10 = l.indexOf('G10 L20 P0 X0 Y0'), g92 = l.indexOf('G92 X0 Y0'); \
                 const taken = (i) => i >= 0 && l.slice(i + 1).includes('ok'); \
                 return (g92 > g10 && l.slice(g10, g92).some(t => t.startsWith('error:20')) && taken(g92)) \
                     || (g10 >= 0 && g92 < 0 && l[g10 + 1] === 'ok') ? l.slice(g10) : null"
            ),
        )
        .await;
    eprintln!("studio work zero: {zero}");
    // The jog button: held jogs, released cancels (0x85).
    let x0 = b.js("return S.status.mpos[0]").await.as_f64().unwrap();
    let pointer = |what: &str| {
        format!(
            "document.querySelector('[data-testid=\"jog-x+\"]').dispatchEvent(new PointerEvent('{what}', {{bubbles: true}})); return true"
        )
    };
    b.js(&pointer("pointerdown")).await;
    b.until(
        "jogging",
        Duration::from_secs(10),
        &format!("return S.status.mpos[0] > {x0} + 0.01"),
    )
    .await;
    b.js(&pointer("pointerup")).await;
    b.until(
        "jog cancel sent",
        Duration::from_secs(10),
        &format!("return {LOG}.includes('0x85 (jog cancel)')"),
    )
    .await;
    idle(&b).await;
    let x1 = b.js("return S.status.mpos[0]").await.as_f64().unwrap();
    assert!(x1 > x0 && x1 <= x0 + 1.0 + 0.03, "jogged from {x0} to {x1}");
    b.screenshot("console.png").await;

    // A second window watches; taking over is explicit.
    let first = b.client.window().await.unwrap();
    let second = b.client.new_window(true).await.unwrap().handle;
    b.client.switch_to_window(second).await.unwrap();
    b.client.goto(&studio.url).await.unwrap();
    b.until("watching", Duration::from_secs(10),
        "return S.connected && S.controller && S.controller !== S.client && !document.getElementById('take-over').hidden").await;
    assert!(b.text("control").await.starts_with("watching"));
    assert!(
        b.js("return document.getElementById('send').disabled")
            .await
            == true
    );
    b.click_until(
        "take-over",
        "controlling",
        10,
        "return S.controller === S.client && document.getElementById('take-over').hidden",
    )
    .await;
    b.assert_no_console_errors().await;
    b.client.close_window().await.unwrap();
    b.client.switch_to_window(first).await.unwrap();
    // Its page closed, control is free again: the first window acts.
    b.until(
        "control free",
        Duration::from_secs(10),
        "return !S.controller",
    )
    .await;

    // Machine selection: `$machine=`, the table read again.
    b.js("document.getElementById('machine-select').value = 'drum'; return true")
        .await;
    b.click_until("machine-switch", "the drum", 60, "return S.settings.includes('$machine=drum') && document.getElementById('machine-select').value === 'drum'").await;

    // An SVG (Inkscape's layers) opens at its own size: the drawing on
    // the left, its toolpath on the right, a pass a layer.
    b.open_file(&example("svg", "inkscape-layers.svg")).await;
    b.until(
        "the SVG's toolpath",
        Duration::from_secs(30),
        "return S.drawing && S.drawing.svg && document.getElementById('v-figures').textContent.includes('3 passes')",
    )
    .await;
    let shown = b
        .js("const i = document.getElementById('input-image'); return [i.complete && i.naturalWidth > 0, document.getElementById('v-width').value]")
        .await;
    assert_eq!(shown, serde_json::json!([true, "120"]));
    b.screenshot("svg.png").await;
    b.assert_no_console_errors().await;
    // A broken one is refused with where.
    b.js("const f = new File(['<svg xmlns=\"http://www.w3.org/2000/svg\"><path d=\"M0 0\"></svg>'], 'broken.svg'); \
          openFile(f); return true").await;
    let refused = b.until("the refusal", Duration::from_secs(10),
        "const n = document.getElementById('notice'); return !n.hidden && n.textContent.includes('SVG') ? n.textContent : null").await;
    assert_eq!(
        refused,
        "vectorise: SVG: expected 'path' tag, not 'svg' at 1:56"
    );
    // The refusal (400) is the one error the browser logged.
    b.assert_no_console_errors_but(Some("/api/vectorize?"))
        .await;
    b.close().await;
    studio.end().await;
}
