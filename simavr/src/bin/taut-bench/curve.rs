//! The fine curve: `fine_curve_*`. 2 000 pieces of 0.1 mm along a gentle
//! arc (R 150 mm, 0.04° a piece) on the flatbed at its top feed, streamed
//! by character counting: the pen's mean feed from the first step to the
//! last. Beside it the same lines through the firmware's parser, executor
//! and planner on the host (`GcodeTime`, no CPU or UART limit) at the
//! firmware's depth and at Grbl-Mega's 36 blocks: how fast the look-ahead
//! lets the machine go, and how close the firmware comes to it.

use crate::stream::{chords, lines, over_serial, print_profile, ready, send, underruns};
use crate::{rises, round};
use serde_json::{json, Map, Value};
use std::path::Path;
use std::time::Duration;
use taut_logic::axis::Axis;
use taut_logic::config::MachineConfig;
use taut_logic::interp::estimate::GcodeTime;
use taut_logic::machine::Machine;
use taut_logic::planner::PLANNER_BLOCKS;

const PIECES: usize = 2000;
const PIECE_MM: f64 = 0.1;
const RADIUS_MM: f64 = 150.0;
/// Inside the flatbed's 140 mm of X: x from 135 mm down to 21 mm.
const CENTRE: [f64; 2] = [-15.0, 0.0];
/// Grbl-Mega's planner depth (`BLOCK_BUFFER_SIZE` for the 2560).
pub(crate) const GRBL_MEGA_BLOCKS: usize = 36;

/// The flatbed's top feed, mm/min: its axes' `max_rate` (the same on
/// both) over their steps per mm.
fn top_feed(cfg: &MachineConfig) -> u32 {
    let x = &cfg.axes[0];
    (x.max_rate as f64 / x.steps_per_unit.as_f32() as f64 * 60.0).round() as u32
}

/// The path's length, mm: its chords between the rounded points.
fn length(points: &[[f64; 2]]) -> f64 {
    points
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .sum()
}

/// Seconds the lines take on the host with a planner `N` blocks deep,
/// from standing at the start to standing at the end.
fn host_seconds<const N: usize>(cfg: &MachineConfig, start: [f64; 2], lines: &[String]) -> f64 {
    let mut t = GcodeTime::<N>::with_depth(cfg).expect("kinematics");
    // `G4 P0` waits for the machine to stand at the start.
    t.push(format!("G90 G21\nG0 X{} Y{}\nG4 P0\n", start[0], start[1]).as_bytes());
    let before = t.seconds();
    for l in lines {
        t.push(format!("{l}\n").as_bytes());
    }
    assert_eq!(t.refused, 0);
    t.finish() - before
}

/// The firmware's seconds from the curve's first step to its last, and
/// the underruns it counted meanwhile.
fn firmware_seconds(elf: &Path, start: [f64; 2], lines: &[String]) -> (f64, u64) {
    let mut sim = ready(elf, Machine::Flatbed, start, None);
    let axes = [Axis::Base, Axis::Radial];
    let before = axes.map(|a| rises(&sim, a).len());
    let under = underruns(&sim);
    let profile = std::env::var("TAUT_BENCH_PROFILE").ok();
    if profile.is_some() {
        sim.enable_call_profile(elf).unwrap();
    }
    over_serial(&mut sim, lines);
    send(&mut sim, "M400");
    // The logger's next report.
    sim.run_for(Duration::from_millis(1100));
    if let (Some(n), Some(p)) = (profile, sim.profile()) {
        print_profile(elf, p, n.parse().unwrap_or(30));
    }
    let (mut first, mut last) = (u64::MAX, 0);
    for (a, n) in axes.iter().zip(before) {
        let r = rises(&sim, *a);
        if let (Some(f), Some(l)) = (r[n..].first(), r[n..].last()) {
            (first, last) = (first.min(*f), last.max(*l));
        }
    }
    ((last - first) as f64 / 16e6, underruns(&sim) - under)
}

pub fn curve_figures(elf: &Path, f: &mut Map<String, Value>) {
    let cfg = MachineConfig::defaults(Machine::Flatbed);
    let feed = top_feed(&cfg);
    let points = chords(CENTRE, RADIUS_MM, PIECE_MM, PIECES);
    let lines = lines(&points, feed);
    let mm = length(&points);
    let per_min = |s: f64| round(mm / s * 60.0, 0);
    let own = per_min(host_seconds::<PLANNER_BLOCKS>(&cfg, points[0], &lines));
    let grbl = per_min(host_seconds::<GRBL_MEGA_BLOCKS>(&cfg, points[0], &lines));
    let (seconds, under) = firmware_seconds(elf, points[0], &lines);
    let firmware = per_min(seconds);
    println!(
        "fine curve at F{feed}: firmware {firmware} mm/min ({under} underruns), host {own} \
         at {PLANNER_BLOCKS} blocks, {grbl} at {GRBL_MEGA_BLOCKS}"
    );
    f.insert("planner_blocks".into(), json!(PLANNER_BLOCKS));
    f.insert("fine_curve_top_feed_mm_per_min".into(), json!(feed));
    f.insert("fine_curve_feed_mm_per_min".into(), json!(firmware));
    f.insert("fine_curve_underruns".into(), json!(under));
    f.insert("fine_curve_host_feed_mm_per_min".into(), json!(own));
    f.insert("fine_curve_host_36_feed_mm_per_min".into(), json!(grbl));
    f.insert(
        "fine_curve_feed_ratio".into(),
        json!(round(firmware / own, 3)),
    );
}
