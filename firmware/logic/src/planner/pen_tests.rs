//! The pen's path on the machines whose kinematics are not linear: a
//! straight line's pieces are planned at the pen's feed and acceleration,
//! and every joint stays within its own limits.

use super::*;
use crate::kinematics::{AnyKinematics, Kinematics, Piece, Segmenter};
use crate::machine::Machine;
use crate::segment::SUBTICKS_PER_S;
use proptest::prelude::*;
use std::vec::Vec;

fn at(x: f64, y: f64) -> Position {
    [
        Milli((x * 1000.0).round() as i32),
        Milli((y * 1000.0).round() as i32),
        Milli(0),
    ]
}

/// Every block of the line `from → to` at `feed` (mm/min, 0: rapid),
/// from rest to rest, standing at `from` first: its figures and its
/// trapezoid's seconds.
fn line(cfg: &MachineConfig, from: Position, to: Position, feed: i32) -> Vec<(Taken, f64)> {
    let kin = AnyKinematics::of(cfg).unwrap();
    let mut p = Planner::new(cfg);
    p.set_position(kin.inverse(&from).unwrap());
    let feed = match feed {
        0 => Feed::Rapid,
        f => Feed::PerMinute(Milli(f * 1000)),
    };
    let path = Segmenter::new(&kin, from, &to, kin.piece_um());
    let mut out = Vec::new();
    let mut take = |p: &mut Planner| {
        let t = p.take_speeds().unwrap();
        let profile = Trapezoid::new(t.block.events, t.accel, &t.speeds);
        let s = profile.time(t.block.events) as f64 / SUBTICKS_PER_S as f64;
        out.push((t, s));
    };
    // As the executor queues a line's pieces.
    for end in path {
        if p.is_full() {
            take(&mut p);
        }
        let (steps, frac) = kin.inverse_fine(&end).unwrap();
        let piece = Piece {
            start: from,
            to: end,
            steps,
            frac,
        };
        p.push_piece(&piece, feed).unwrap();
    }
    while p.queued() > 0 {
        take(&mut p);
    }
    out
}

/// The closed-form trapezoid: `length` mm at `feed` mm/min, `accel` mm/s².
fn trapezoid_s(length: f64, feed: f64, accel: f64) -> f64 {
    let v = feed / 60.0;
    match v * v / accel >= length {
        true => 2.0 * (length / accel).sqrt(),
        false => v / accel + length / v,
    }
}

fn seconds(blocks: &[(Taken, f64)]) -> f64 {
    blocks.iter().map(|b| b.1).sum()
}

/// What the blocks ask of each joint and the pen: every joint's speed
/// and acceleration within its own limits, the pen's speed within
/// `feed` (mm/min) and its acceleration within `pen_accel`.
fn assert_within_limits(cfg: &MachineConfig, blocks: &[(Taken, f64)], feed: f64) {
    for (t, _) in blocks {
        let e = t.block.events as f64;
        let cruise = (t.speeds.cruise_sqr as f64).sqrt();
        for i in 0..AXES {
            let share = t.block.steps[i] as f64 / e;
            let a = &cfg.axes[i];
            assert!(cruise * share <= a.max_rate as f64 + 1.0, "{t:?}");
            assert!(t.accel as f64 * share <= a.accel as f64 + 1.0, "{t:?}");
        }
        let k = (t.ev_per_milli_sqr as f64).sqrt();
        let pen = cruise / k / 1000.0;
        assert!(pen <= feed / 60.0 * 1.0001 + 1e-3, "{pen} mm/s");
        let accel = t.accel as f64 / k / 1000.0;
        assert!(
            accel <= cfg.pen_accel as f64 * 1.0001 + 1e-3,
            "{accel} mm/s²"
        );
    }
}

/// The user's lines: 40 mm at F600 took 2.38 s and 1.11 s on the arm
/// (the planner's path was then the joints' degrees), 4.1 s on the
/// flatbed. Now the pen's trapezoid: 10 mm/s, ramps at 100 mm/s².
#[test]
fn the_arms_40_mm_at_f600_take_the_pens_trapezoid() {
    let cfg = MachineConfig::defaults(Machine::Scara);
    let ideal = trapezoid_s(40.0, 600.0, cfg.pen_accel as f64);
    for (from, to) in [
        ((80.0, 150.0), (80.0, 190.0)),
        ((60.0, 200.0), (100.0, 200.0)),
    ] {
        let blocks = line(&cfg, at(from.0, from.1), at(to.0, to.1), 600);
        let s = seconds(&blocks);
        assert!(
            (s / ideal - 1.0).abs() < 0.002,
            "{from:?} → {to:?}: {s} s, not {ideal}"
        );
        assert_within_limits(&cfg, &blocks, 600.0);
    }
}

/// The whiteboard's pen the same, at its own acceleration.
#[test]
fn the_whiteboards_lines_take_the_pens_trapezoid() {
    let cfg = MachineConfig::defaults(Machine::Whiteboard);
    for (to, feed) in [((40.0, 0.0), 600.0), ((-200.0, 150.0), 3000.0)] {
        let blocks = line(&cfg, at(0.0, 0.0), at(to.0, to.1), feed as i32);
        let length = to.0.hypot(to.1);
        let ideal = trapezoid_s(length, feed, cfg.pen_accel as f64);
        let s = seconds(&blocks);
        assert!(
            (s / ideal - 1.0).abs() < 0.002,
            "{to:?}: {s} s, not {ideal}"
        );
        assert_within_limits(&cfg, &blocks, feed);
    }
}

/// A rapid runs at `pen_max_feed` where the joints allow it.
#[test]
fn a_rapid_is_the_pens_top_speed() {
    let mut cfg = MachineConfig::defaults(Machine::Whiteboard);
    cfg.pen_max_feed = 3000;
    let blocks = line(&cfg, at(0.0, 0.0), at(0.0, -300.0), 0);
    let ideal = trapezoid_s(300.0, 3000.0, cfg.pen_accel as f64);
    let s = seconds(&blocks);
    assert!((s / ideal - 1.0).abs() < 0.002, "{s} s, not {ideal}");
    assert_within_limits(&cfg, &blocks, 3000.0);
}

/// Radially out to the arm's reach, its elbow straightening: the elbow's
/// share of the pen's speed grows without bound, and the pen slows so
/// that it keeps to its rate and acceleration.
#[test]
fn near_full_reach_the_elbow_holds_the_pen_back() {
    let cfg = MachineConfig::defaults(Machine::Scara);
    // The shoulder at (100, −56), arms 150 + 150: out to 299 mm.
    let blocks = line(&cfg, at(100.0, 144.0), at(100.0, 243.0), 3000);
    assert_within_limits(&cfg, &blocks, 3000.0);
    let ideal = trapezoid_s(99.0, 3000.0, cfg.pen_accel as f64);
    let s = seconds(&blocks);
    assert!(
        s > 1.1 * ideal,
        "{s} s: the elbow did not hold it back ({ideal} s)"
    );
    // The elbow at its top rate somewhere.
    let top = blocks
        .iter()
        .map(|(t, _)| {
            (t.speeds.cruise_sqr as f64).sqrt() * t.block.steps[1] as f64 / t.block.events as f64
        })
        .fold(0.0, f64::max);
    assert!(
        top > 0.9 * cfg.axes[1].max_rate as f64,
        "elbow at most {top} steps/s"
    );
}

/// On a machine whose kinematics are linear a piece is planned as the
/// move to its steps: the same blocks, to the bit.
#[test]
fn linear_machines_plan_pieces_as_moves() {
    for m in [Machine::Flatbed, Machine::Drum, Machine::StringArt] {
        let cfg = MachineConfig::defaults(m);
        let (mut a, mut b) = (Planner::new(&cfg), Planner::new(&cfg));
        for (k, target) in [[400, 0, 0], [400, 300, 0], [-100, 20, 7]]
            .iter()
            .enumerate()
        {
            let piece = Piece {
                start: at(k as f64, 0.0),
                to: at(k as f64 + 1.0, 3.0),
                steps: *target,
                frac: [5, -7, 0],
            };
            let feed = Feed::PerMinute(Milli(600_000));
            a.push(*target, feed).unwrap();
            b.push_piece(&piece, feed).unwrap();
        }
        while let Some(t) = a.take_speeds() {
            let u = b.take_speeds().unwrap();
            assert_eq!(std::format!("{t:?}"), std::format!("{u:?}"), "{m:?}");
        }
        assert!(b.take_speeds().is_none());
    }
}

/// The curvature limit: a joint whose share of the pen's speed changes by
/// Δ over `len` is accelerated by v²·Δ / len; a sudden change of Δ is
/// the joint's jump, v·Δ.
#[test]
fn a_joints_share_changing_limits_the_speed_to_its_acceleration() {
    let cfg = MachineConfig::defaults(Machine::Scara);
    let g = junction::Geometry::new(&cfg);
    let j = axis_jump::AxisJumps::new(&cfg);
    // 26.67 steps per degree: 0.0375 mdeg a step. The shoulder's share
    // changes by 0.01 mdeg/µm over 2000 µm; its 2000 steps/s² are
    // 75 000 mdeg/s²: v² = 75 000 · 2000 / 0.01 (µm/s)².
    let v2 = g.joints_sqr(&j, &[0.2, 0.1, 0.0], &[0.21, 0.1, 0.0], 2000.0);
    let want = 75_000.0 * 2000.0 / 0.01;
    assert!((v2 as f64 / want - 1.0).abs() < 1e-4, "{v2} vs {want}");
    // Spread over 100 mm, the jump binds: √(2·2000·8) = 179 steps/s,
    // 6708 mdeg/s, at v·0.01 mdeg/µm.
    let v2 = g.joints_sqr(&j, &[0.2, 0.1, 0.0], &[0.21, 0.1, 0.0], 100_000.0);
    let want = (6708.2 / 0.01f64).powi(2);
    assert!((v2 as f64 / want - 1.0).abs() < 1e-3, "{v2} vs {want}");
    assert_eq!(
        g.joints_sqr(&j, &[0.2, 0.1, 0.0], &[0.2, 0.1, 0.0], 2000.0),
        f32::INFINITY
    );
}

fn reachable() -> impl Strategy<Value = (f64, f64)> {
    // In front of the arm's base, 60–260 mm from the shoulder (100, −56).
    (60.0f64..260.0, -1.3f64..1.3).prop_map(|(r, b)| (100.0 - r * b.sin(), -56.0 + r * b.cos()))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Any line the arm reaches, at any feed: no joint and not the pen
    /// past its limits, never faster than the pen's trapezoid, and at it
    /// (within 1 %, the look-ahead of 12 pieces of 2 mm being deep
    /// enough to stop from F3000 at 100 mm/s²) where the joints allow.
    #[test]
    fn arm_lines_keep_every_limit(a in reachable(), b in reachable(), feed in 300i32..3000) {
        let cfg = MachineConfig::defaults(Machine::Scara);
        let kin = AnyKinematics::of(&cfg).unwrap();
        let (from, to) = (at(a.0, a.1), at(b.0, b.1));
        prop_assume!(kin.reaches_line(&from, &to));
        let length = (b.0 - a.0).hypot(b.1 - a.1);
        prop_assume!(length > 1.0);
        let blocks = line(&cfg, from, to, feed);
        assert_within_limits(&cfg, &blocks, feed as f64);
        let ideal = trapezoid_s(length, feed as f64, cfg.pen_accel as f64);
        prop_assert!(seconds(&blocks) >= ideal * 0.995, "{} s, ideal {ideal}", seconds(&blocks));
    }

    /// The same on the whiteboard, whose chains never bind at its
    /// defaults: every line at the pen's trapezoid.
    #[test]
    fn whiteboard_lines_keep_every_limit(
        x0 in -500.0f64..500.0, y0 in -500.0f64..300.0,
        x1 in -500.0f64..500.0, y1 in -500.0f64..300.0, feed in 300i32..3000,
    ) {
        let cfg = MachineConfig::defaults(Machine::Whiteboard);
        let length = (x1 - x0).hypot(y1 - y0);
        prop_assume!(length > 1.0);
        let blocks = line(&cfg, at(x0, y0), at(x1, y1), feed);
        assert_within_limits(&cfg, &blocks, feed as f64);
        let ideal = trapezoid_s(length, feed as f64, cfg.pen_accel as f64);
        let s = seconds(&blocks);
        prop_assert!((s / ideal - 1.0).abs() < 0.01, "{s} s, ideal {ideal}");
    }
}
