use super::*;
use crate::axis::{PerAxis, AXES};
use crate::config::square;
use crate::planner::{Feed, Full};
use crate::segment::{expand, Event, TICK_HZ};
use proptest::prelude::*;
use std::vec::Vec;

const ACCEL: f64 = 1000.0;

/// What a run produced: the replayed events, how many were cut when the
/// hold was asked and when it stood.
struct Run {
    events: Vec<Event>,
    /// Events before each block's first.
    block_starts: Vec<usize>,
    held_at: Option<usize>,
    stood_at: Option<usize>,
}

/// Plans `moves` and cuts them; after `hold_after` events are cut, holds,
/// cuts until the stop, then resumes (or `resume_early`: right after the
/// hold, while still braking) and cuts the rest.
fn run(moves: &[PerAxis<i32>], hold_after: usize, resume_early: bool) -> Run {
    run_as(moves, hold_after, resume_early, false)
}

/// The firmware's way: one bounded piece of work per call ([`Prep::load`],
/// [`Prep::next_part`]); at most `MAX_PIECES` calls a segment.
const MAX_PIECES: usize = 12;

std::thread_local! {
    /// What [`others_wait`] says in this test's thread.
    static OTHERS_WAIT: core::cell::Cell<bool> = const { core::cell::Cell::new(false) };
}

/// The app's "another task waits" ([`Prep::yield_to`]), as the test sets it.
fn others_wait() -> bool {
    OTHERS_WAIT.with(|w| w.get())
}

/// Calls of [`Prep::load`] and [`Prep::next_part`] to cut `moves` whole.
fn bounded_calls(prep: &mut Prep, moves: &[PerAxis<i32>]) -> usize {
    let mut planner = Planner::new(&square());
    for m in moves {
        planner.push(*m, Feed::Rapid).unwrap();
    }
    let mut calls = 0;
    loop {
        calls += 1;
        if prep.load(&mut planner) {
            continue;
        }
        match prep.next_part(&mut planner) {
            Err(Later) | Ok(Some(_)) => {}
            Ok(None) => return calls,
        }
    }
}

/// A call that worked out an event time ends before the fit while another
/// task waits: more calls, the same segments (the proptest below), and a
/// cleared preparer (a stop at once) still yields.
#[test]
fn a_waiting_task_ends_a_call_before_the_fit() {
    let moves: Vec<PerAxis<i32>> = (1..=3).map(|k| [k * 2000, k * 700, 0]).collect();
    let mut prep = Prep::new();
    prep.yield_to(others_wait);
    let alone = bounded_calls(&mut prep, &moves);
    OTHERS_WAIT.with(|w| w.set(true));
    prep.clear();
    let yielding = bounded_calls(&mut prep, &moves);
    OTHERS_WAIT.with(|w| w.set(false));
    assert!(
        yielding > alone + 10,
        "{alone} calls alone, {yielding} yielding"
    );
}

fn next_bounded(prep: &mut Prep, planner: &mut Planner) -> Option<Cut> {
    for _ in 0..MAX_PIECES {
        if prep.load(planner) {
            continue;
        }
        match prep.next_part(planner) {
            Err(Later) => continue,
            Ok(cut) => return cut,
        }
    }
    panic!("a segment took more than {MAX_PIECES} calls");
}

fn run_as(moves: &[PerAxis<i32>], hold_after: usize, resume_early: bool, bounded: bool) -> Run {
    let mut planner = Planner::new(&square());
    let mut prep = Prep::new();
    prep.yield_to(others_wait);
    let (mut segs, mut blocks) = (Vec::new(), Vec::new());
    let mut cut_events = 0usize;
    let (mut held_at, mut stood_at) = (None, None);
    let mut pending = moves.iter();
    let mut next_move = pending.next();
    loop {
        // Keep the planner full, as a sender does.
        while let Some(&m) = next_move {
            match planner.push(m, Feed::Rapid) {
                Ok(()) => next_move = pending.next(),
                Err(Full) => break,
            }
        }
        if held_at.is_none() && cut_events >= hold_after {
            held_at = Some(cut_events);
            prep.hold();
            if resume_early {
                assert!(prep.resume(&mut planner));
            }
        }
        let next = match bounded {
            true => next_bounded(&mut prep, &mut planner),
            false => prep.next(&mut planner),
        };
        match next {
            Some(c) => {
                blocks.extend(c.block);
                cut_events += c.segment.count as usize;
                segs.push(c.segment);
            }
            None if prep.hold_state() == Hold::Stopped => {
                assert!(stood_at.is_none(), "one stop");
                stood_at = Some(cut_events);
                assert!(prep.resume(&mut planner));
            }
            None => {
                assert!(next_move.is_none() && planner.is_idle() && prep.is_idle());
                break;
            }
        }
    }
    let block_starts = blocks
        .iter()
        .scan(0, |at, b: &StepBlock| {
            let start = *at;
            *at += b.events as usize;
            Some(start)
        })
        .collect();
    Run {
        events: expand(segs, blocks).collect(),
        block_starts,
        held_at,
        stood_at,
    }
}

fn travel(events: &[Event]) -> PerAxis<i32> {
    let mut pos = [0; AXES];
    for e in events {
        for (i, p) in pos.iter_mut().enumerate() {
            if e.axes >> i & 1 != 0 {
                *p += if e.dir >> i & 1 != 0 { 1 } else { -1 };
            }
        }
    }
    pos
}

/// Speed after each event from the interval to the next, events/s.
fn speeds(events: &[Event]) -> Vec<f64> {
    events
        .windows(2)
        .map(|w| TICK_HZ as f64 / (w[1].tick - w[0].tick) as f64)
        .collect()
}

#[test]
fn a_hold_mid_cruise_brakes_to_a_stop_and_resume_ends_on_target() {
    let target = [40_000, 0, 0];
    let r = run(&[target], 20_000, false);
    assert_eq!(travel(&r.events), target);
    let (held, stood) = (r.held_at.unwrap(), r.stood_at.unwrap());
    // Cruising at 4000 steps/s: the stop takes v²/2a = 8000 events.
    let braking = stood - held;
    assert!((7990..=8010).contains(&braking), "{braking} events to stop");
    let v = speeds(&r.events);
    // Braking: the speed falls at every event until the stop.
    assert!(v[held..stood - 1].windows(2).all(|w| w[1] <= w[0] + 1.0));
    assert!(v[stood - 2] < 100.0, "stands: {}", v[stood - 2]);
}

#[test]
fn a_hold_near_the_end_of_a_short_block_brakes_on_into_the_next() {
    // Blocks of 2000 steps straight on: the stop (8000 events) spans four.
    let moves: Vec<PerAxis<i32>> = (1..=8).map(|k| [k * 2000, k * 2000, 0]).collect();
    let r = run(&moves, 9_000, false);
    assert_eq!(travel(&r.events), [16_000, 16_000, 0]);
    let (held, stood) = (r.held_at.unwrap(), r.stood_at.unwrap());
    assert!(stood > held + 2000, "braked across blocks: {held}..{stood}");
}

#[test]
fn resume_while_braking_goes_on_from_the_stop() {
    let target = [0, 30_000, 0];
    let r = run(&[target], 15_000, true);
    assert_eq!(travel(&r.events), target);
    assert!(r.stood_at.is_none(), "resumed at once: no stop reported");
}

#[test]
fn a_hold_with_nothing_moving_is_a_stop_at_once() {
    let mut planner = Planner::new(&square());
    let mut prep = Prep::new();
    prep.hold();
    assert_eq!(prep.next(&mut planner), None);
    assert_eq!(prep.hold_state(), Hold::Stopped);
    planner.push([100, 0, 0], Feed::Rapid).unwrap();
    assert_eq!(prep.next(&mut planner), None, "held: nothing starts");
    assert!(prep.resume(&mut planner));
    assert!(prep.next(&mut planner).is_some_and(|c| c.block.is_some()));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Any moves, a hold at any moment, resumed at the stop: every step
    /// of every move is made, and the braking never exceeds the
    /// acceleration (speeds from the replayed event times).
    #[test]
    fn holds_keep_every_step_and_brake_within_the_acceleration(
        moves in proptest::collection::vec((-3000i32..3000, -3000i32..3000), 1..6),
        hold_frac in 0.0f64..1.0,
        early in any::<bool>(),
        yielding in any::<bool>(),
    ) {
        OTHERS_WAIT.with(|w| w.set(yielding));
        let mut at = [0i32; AXES];
        let targets: Vec<PerAxis<i32>> = moves
            .iter()
            .map(|&(x, y)| {
                at[0] += x;
                at[1] += y;
                at
            })
            .collect();
        let total: usize = {
            let mut prev = [0i32; AXES];
            targets
                .iter()
                .map(|t| {
                    let n = (t[0] - prev[0]).unsigned_abs().max((t[1] - prev[1]).unsigned_abs());
                    prev = *t;
                    n as usize
                })
                .sum()
        };
        let r = run(&targets, (hold_frac * total as f64) as usize, early);
        // Cut in bounded pieces (ending before a fit when `yielding`), the
        // same events at the same times.
        let b = run_as(&targets, (hold_frac * total as f64) as usize, early, true);
        prop_assert!(b.events == r.events, "bounded pieces cut other events");
        prop_assert_eq!(travel(&r.events), at);
        prop_assert_eq!(r.events.len(), total);
        if let (Some(held), Some(stood)) = (r.held_at, r.stood_at) {
            // Braking: v² falls by 2a per event at most, measured over
            // windows of 16 events (single intervals carry the 4 µs
            // timing tolerance) away from the stop (where a window's mean
            // speed is no longer the speed at its middle), and inside a
            // block (the event rate jumps at a corner where the path
            // speed does not).
            let w = 16;
            let t: Vec<f64> = r.events.iter().map(|e| e.tick as f64 / TICK_HZ as f64).collect();
            let v = |j: usize| w as f64 / (t[j + w] - t[j]);
            let mut j = held;
            while j + 2 * w < stood {
                let (a, b) = (v(j), v(j + w));
                if b * b < 2.0 * ACCEL * (4 * w) as f64 {
                    break;
                }
                let corner = r.block_starts.iter().any(|&s| s > j && s <= j + 2 * w);
                prop_assert!(
                    corner || (a * a - b * b) / (2.0 * w as f64) <= ACCEL * 1.05,
                    "events {}..{}: {} -> {} steps/s", j, j + 2 * w, a, b
                );
                j += w;
            }
        }
    }
}

/// A hold while a block's profile is half made: it is finished, and the
/// braking starts from the block's entry speed; every step still made.
#[test]
fn a_hold_while_a_profile_is_made_brakes_from_its_entry() {
    let moves: Vec<PerAxis<i32>> = (1..=6).map(|k| [k * 3000, 0, 0]).collect();
    let mut planner = Planner::new(&square());
    for m in &moves {
        planner.push(*m, Feed::Rapid).unwrap();
    }
    let mut prep = Prep::new();
    let (mut segs, mut blocks) = (Vec::new(), Vec::new());
    // The first block cut whole, then the second begun.
    loop {
        if prep.load(&mut planner) {
            continue;
        }
        if let Ok(Some(c)) = prep.next_part(&mut planner) {
            blocks.extend(c.block);
            segs.push(c.segment);
            if prep.is_idle() {
                break;
            }
        }
    }
    assert!(prep.load(&mut planner), "the second block begun");
    prep.hold();
    loop {
        match next_bounded(&mut prep, &mut planner) {
            Some(c) => {
                blocks.extend(c.block);
                segs.push(c.segment);
            }
            None if prep.hold_state() == Hold::Stopped => {
                assert!(prep.resume(&mut planner));
            }
            None => break,
        }
    }
    let events: Vec<Event> = expand(segs, blocks).collect();
    assert_eq!(travel(&events), [18_000, 0, 0]);
}

/// A block half loaded is work still to do: segment preparation must run on
/// (and `M400` wait) until its profile is made and cut.
#[test]
fn a_half_loaded_block_is_not_idle() {
    let mut planner = Planner::new(&square());
    planner.push([9600, 0, 0], Feed::Rapid).unwrap();
    let mut prep = Prep::new();
    assert!(prep.is_idle());
    assert!(prep.load(&mut planner));
    assert!(planner.is_idle(), "taken from the planner");
    assert!(!prep.is_idle(), "its profile is still being made");
}
