use super::*;
use crate::config::square;
use crate::segment::{expand, Event, Preparer, Segment, TICK_HZ};
use proptest::prelude::*;
use std::vec::Vec;

fn entries(p: &Planner) -> Vec<u64> {
    (0..p.len)
        .map(|i| (p.blocks[(p.head + i) % PLANNER_BLOCKS].entry_sqr as u64) << p.shift)
        .collect()
}

/// Nominal path speed² of a 4000 steps/s move on one axis of `square()`:
/// 40 units/s = 40 000 milli/s.
const FULL_SQR: u64 = 40_000 * 40_000;

#[test]
fn speeds_of_a_fast_machine_are_kept_shifted() {
    // 10 steps/unit at 100 000 steps/s: 10 000 units/s on each axis,
    // 10⁷ milli/s; 4·10¹⁴ squared on the four: 32 bits only shifted
    // right by 17.
    let mut c = square();
    for a in &mut c.axes {
        a.steps_per_unit = crate::units::StepsPerUnit::new(10, 1);
        a.max_rate = 100_000;
        a.accel = 100_000;
    }
    let mut p = Planner::new(&c);
    assert_eq!(p.shift, 17);
    for k in 1..=3 {
        p.push([k * 200_000, 0, 0], Feed::Rapid).unwrap();
    }
    let e = entries(&p);
    let full = 1e14;
    assert_eq!(e[0], 0);
    assert!((e[1] as f64 - full).abs() < full * 1e-4, "{e:?}");
    let t = p.take_speeds().unwrap();
    let cruise = 100_000f64 * 100_000.0;
    assert!(
        (t.speeds.cruise_sqr as f64 - cruise).abs() < cruise * 1e-4,
        "{t:?}"
    );
    assert!(
        (t.speeds.exit_sqr as f64 - cruise).abs() < cruise * 1e-4,
        "{t:?}"
    );
}

#[test]
fn straight_on_keeps_full_speed() {
    let mut p = Planner::new(&square());
    for k in 1..=3 {
        p.push([k * 20_000, 0, 0], Feed::Rapid).unwrap();
    }
    let e = entries(&p);
    assert_eq!(e[0], 0);
    // 20 000 steps at 1000/s² reach 4000 steps/s; the junctions run at it.
    assert!(e[1].abs_diff(FULL_SQR) <= FULL_SQR / 100_000, "{e:?}");
    assert!(e[2].abs_diff(FULL_SQR) <= FULL_SQR / 100_000, "{e:?}");
}

#[test]
fn right_angle_takes_the_lower_of_grbl_and_the_axis_jumps() {
    let mut p = Planner::new(&square());
    p.push([20_000, 0, 0], Feed::Rapid).unwrap();
    p.push([20_000, 20_000, 0], Feed::Rapid).unwrap();
    // Grbl: a = 1000 steps/s² = 10 000 milli/s² per axis, limited along the
    // velocity change (-1, 1)/√2 → a·√2; sin(θ/2) = √½.
    let a = 10_000.0 * 2f64.sqrt();
    let s = 0.5f64.sqrt();
    let grbl = a * 50.0 * s / (1.0 - s);
    // Each axis's velocity changes by the whole path speed: at most
    // √(2·1000·8) = 126.5 steps/s = 1265 milli/s (`axis_jump`), below
    // Grbl's 1307.
    let jump = (2.0 * 1000.0 * 8.0f64).sqrt() * 10.0;
    let expected = grbl.min(jump * jump);
    assert!(expected < grbl);
    let got = entries(&p)[1] as f64;
    assert!(
        (got - expected).abs() < expected * 1e-4,
        "{got} vs {expected}"
    );
    assert!(got > 0.0 && (got as u64) < FULL_SQR);
}

#[test]
fn reversal_stops() {
    let mut p = Planner::new(&square());
    p.push([20_000, 0, 0], Feed::Rapid).unwrap();
    p.push([0, 0, 0], Feed::Rapid).unwrap();
    p.push([20_000, 0, 0], Feed::Rapid).unwrap();
    assert_eq!(entries(&p), [0, 0, 0]);
}

#[test]
fn gentle_corner_does_not_stop() {
    let mut p = Planner::new(&MachineConfig::STRING_ART);
    p.push([9600, 320, 0], Feed::Rapid).unwrap();
    p.push([19_200, 680, 0], Feed::Rapid).unwrap();
    let e = entries(&p)[1];
    assert!(e > 0, "{e}");
}

#[test]
fn full_queue_pushes_back() {
    let mut p = Planner::new(&square());
    for k in 1..=PLANNER_BLOCKS as i32 {
        assert_eq!(p.free(), PLANNER_BLOCKS + 1 - k as usize);
        p.push([k * 100, 0, 0], Feed::Rapid).unwrap();
    }
    assert_eq!(p.free(), 0);
    assert_eq!(p.push([0, 0, 0], Feed::Rapid), Err(Full));
    assert!(p.take().is_some());
    assert_eq!(p.push([0, 0, 0], Feed::Rapid), Ok(()));
    assert_eq!(p.position(), [0; AXES]);
}

#[test]
fn a_staged_move_is_planned_in_parts_and_queued_by_the_last() {
    let mut p = Planner::new(&square());
    let mut whole = Planner::new(&square());
    p.push([20_000, 0, 0], Feed::Rapid).unwrap();
    whole.push([20_000, 0, 0], Feed::Rapid).unwrap();
    let second = ([20_000, 20_000, 0], Feed::PerMinute(Milli(600_000)));
    p.stage(second.0, second.1).unwrap();
    // The move being planned holds a block.
    assert_eq!(p.free(), PLANNER_BLOCKS - 2);
    whole.push(second.0, second.1).unwrap();
    assert_eq!(p.position(), second.0);
    let mut parts = 0;
    while p.queued() == 1 {
        // No room and not idle until queued; the preparer sees only the
        // queue.
        assert!(p.is_full() && !p.is_idle());
        assert_eq!(p.stage([0; AXES], Feed::Rapid), Err(Full));
        assert!(p.plan_part());
        parts += 1;
    }
    assert_eq!(parts, 4);
    assert!(!p.plan_part() && !p.is_full());
    assert_eq!(entries(&p), entries(&whole));
    assert_eq!(p.take(), whole.take());
    // A move of no step is dropped at once.
    p.stage(second.0, Feed::Rapid).unwrap();
    assert!(!p.plan_part());
}

#[test]
fn a_block_taken_while_the_next_is_planned_stops_at_its_end() {
    let mut p = Planner::new(&square());
    p.push([20_000, 0, 0], Feed::Rapid).unwrap();
    p.stage([40_000, 0, 0], Feed::Rapid).unwrap();
    assert!(p.plan_part());
    let t = p.take_speeds().unwrap();
    assert_eq!((t.block.steps[0], t.speeds.exit_sqr), (20_000, 0));
    while p.plan_part() {}
    assert_eq!(p.take_speeds().unwrap().block.steps[0], 20_000);
    assert!(p.is_idle());
}

/// Plans `moves`, taking blocks when the queue is full, and replays what
/// the step interrupt would do.
fn run(
    config: &MachineConfig,
    moves: &[(PerAxis<i32>, Feed)],
) -> (Vec<Event>, Vec<StepBlock>, usize) {
    let mut p = Planner::new(config);
    let mut prep = Preparer::new();
    let (mut segs, mut blocks) = (Vec::<Segment>::new(), Vec::new());
    let mut drain = |p: &mut Planner, segs: &mut Vec<Segment>, blocks: &mut Vec<StepBlock>| {
        let planned = p.take().unwrap();
        blocks.push(planned.block);
        prep.start(planned.profile);
        while let Some(s) = prep.next_segment() {
            segs.push(s);
        }
    };
    for &(target, feed) in moves {
        while p.push(target, feed) == Err(Full) {
            drain(&mut p, &mut segs, &mut blocks);
        }
    }
    while !p.is_idle() {
        drain(&mut p, &mut segs, &mut blocks);
    }
    let n = segs.len();
    (expand(segs, blocks.clone()).collect(), blocks, n)
}

/// Net steps per axis of a replay.
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

/// Highest speed and acceleration of an axis rebuilt from its step times
/// over windows of `w` steps, steps/s and steps/s².
fn speed_and_accel(times: &[u64], w: usize) -> (f64, f64) {
    let t: Vec<f64> = times.iter().map(|&t| t as f64 / TICK_HZ as f64).collect();
    let v: Vec<(f64, f64)> = (0..t.len().saturating_sub(w))
        .map(|j| ((t[j] + t[j + w]) / 2.0, w as f64 / (t[j + w] - t[j])))
        .collect();
    let vmax = v.iter().map(|x| x.1).fold(0.0, f64::max);
    let amax = (0..v.len().saturating_sub(w))
        .map(|j| ((v[j + w].1 - v[j].1) / (v[j + w].0 - v[j].0)).abs())
        .fold(0.0, f64::max);
    (vmax, amax)
}

#[test]
fn string_art_turn_profile() {
    let c = MachineConfig::STRING_ART;
    let (events, _, segs) = run(&c, &[([9600, 0, 0], Feed::Rapid)]);
    assert_eq!(travel(&events), [9600, 0, 0]);
    let times: Vec<u64> = events.iter().map(|e| e.tick).collect();
    let (v, a) = speed_and_accel(&times, 128);
    assert!(v <= 2000.0 * 1.001 && v > 1990.0, "{v}");
    assert!(a <= 500.0 * 1.02 && a > 450.0, "{a}");
    std::println!("one turn: {segs} segments");
}

fn moves() -> impl Strategy<Value = Vec<(PerAxis<i32>, Feed)>> {
    let feed = prop_oneof![
        Just(Feed::Rapid),
        (1_000i32..200_000).prop_map(|f| Feed::PerMinute(Milli(f * 100)))
    ];
    proptest::collection::vec((proptest::array::uniform3(-3000i32..3000), feed), 1..40)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn exact_totals_and_final_position(moves in moves()) {
        let (events, blocks, segs) = run(&MachineConfig::STRING_ART, &moves);
        prop_assert_eq!(travel(&events), moves.last().unwrap().0);
        // Every block's DDA makes exactly its steps.
        let total: u64 = blocks.iter().map(|b| b.events as u64).sum();
        prop_assert_eq!(events.len() as u64, total);
        prop_assert!(segs <= events.len());
        // No axis ever runs faster than its 2000 steps/s.
        for i in 0..AXES {
            let times: Vec<u64> = events.iter().filter(|e| e.axes >> i & 1 != 0).map(|e| e.tick).collect();
            let (v, _) = speed_and_accel(&times, 64);
            prop_assert!(v <= 2000.0 * 1.01, "axis {} at {}", i, v);
        }
    }

    #[test]
    fn collinear_moves_never_exceed_limits(
        lengths in proptest::collection::vec(1i32..4000, 1..20),
        feeds in proptest::collection::vec(60_000i32..200_000, 20),
    ) {
        // Base axis forward in pieces at varying feeds (millidegrees/min).
        let mut pos = 0;
        let moves: Vec<_> = lengths.iter().zip(&feeds).map(|(&l, &f)| {
            pos += l;
            ([pos, 0, 0], Feed::PerMinute(Milli(f * 100)))
        }).collect();
        let (events, _, _) = run(&MachineConfig::STRING_ART, &moves);
        prop_assert_eq!(travel(&events)[0], pos);
        let times: Vec<u64> = events.iter().map(|e| e.tick).collect();
        let (v, a) = speed_and_accel(&times, 128);
        prop_assert!(v <= 2000.0 * 1.001, "speed {}", v);
        prop_assert!(a <= 500.0 * 1.02, "accel {}", a);
    }
}

/// The cruise speed of a move taken from the planner, events/s.
fn cruise(p: &mut Planner) -> f64 {
    (p.take().unwrap().profile.cruise_sqr() as f64).sqrt()
}

/// Grbl's overrides act on the moves not yet taken: the feed's from 10
/// to 200 % of `F`, never above the axes' rates; the rapid's 25, 50 or
/// 100 % of the rapid rate, on rapids only.
#[test]
fn overrides_scale_the_moves_not_yet_taken() {
    let mut p = Planner::new(&square());
    // F1200 on an axis of 100 steps/unit: 2000 steps/s; rapids 4000.
    for k in 1..=4 {
        p.push([k * 20_000, 0, 0], Feed::PerMinute(Milli(1_200_000)))
            .unwrap();
    }
    p.push([100_000, 0, 0], Feed::Rapid).unwrap();
    assert!((cruise(&mut p) - 2000.0).abs() < 1.0);
    p.set_overrides(Overrides {
        feed: 50,
        rapid: 25,
    });
    assert!((cruise(&mut p) - 1000.0).abs() < 1.0);
    p.set_overrides(Overrides {
        feed: 150,
        rapid: 25,
    });
    assert!((cruise(&mut p) - 3000.0).abs() < 1.0);
    // 200 % of 2000 would be 4000: the axis's rate.
    p.set_overrides(Overrides {
        feed: 200,
        rapid: 25,
    });
    assert!((cruise(&mut p) - 4000.0).abs() < 1.0);
    assert!((cruise(&mut p) - 1000.0).abs() < 1.0, "the rapid at 25 %");
    // A move queued later gets them too, and the entries follow the new
    // cruise speeds (a junction never faster than either side).
    p.set_overrides(Overrides {
        feed: 10,
        rapid: 100,
    });
    for k in 6..=8 {
        p.push([k * 20_000, 0, 0], Feed::PerMinute(Milli(1_200_000)))
            .unwrap();
    }
    // 200 steps/s at 100 steps a unit: 2 000 milli-units/s.
    let slow = 2000.0 * 2000.0;
    assert!(
        entries(&p)[1..]
            .iter()
            .all(|&e| (e as f64 - slow).abs() < slow * 1e-3),
        "{:?}",
        entries(&p)
    );
    assert!((cruise(&mut p) - 200.0).abs() < 1.0);
}

/// What a planner does to its queue, in a random stream.
#[derive(Clone, Debug)]
enum Op {
    Push(PerAxis<i32>, Feed),
    Take,
    LimitEntry(u64),
    Overrides(u8),
}

fn ops() -> impl Strategy<Value = Vec<Op>> {
    let feed = prop_oneof![
        Just(Feed::Rapid),
        (1_000i32..200_000).prop_map(|f| Feed::PerMinute(Milli(f * 100)))
    ];
    // Short moves, mostly onward along a wandering heading: the queue
    // fills with blocks whose entries are bound by the look-ahead, the
    // junctions and the feeds in turn.
    let op = prop_oneof![
        8 => (proptest::array::uniform3(-400i32..400), feed).prop_map(|(d, f)| Op::Push(d, f)),
        2 => Just(Op::Take),
        1 => (0u64..FULL_SQR).prop_map(Op::LimitEntry),
        1 => (10u8..=200).prop_map(Op::Overrides),
    ];
    proptest::collection::vec(op, 1..300)
}

/// The entries a planner planning every block from the oldest would give.
fn replanned<const N: usize>(p: &Lookahead<N>) -> Vec<u32> {
    let mut full = Lookahead::<N> {
        blocks: p.blocks,
        planned: 0,
        ..Lookahead::EMPTY
    };
    (full.head, full.len, full.carry_sqr) = (p.head, p.len, p.carry_sqr);
    full.recalculate();
    (0..p.len)
        .map(|i| full.blocks[(p.head + i) % N].entry_sqr)
        .collect()
}

fn incremental_matches_full<const N: usize>(ops: &[Op]) -> Result<(), TestCaseError> {
    let mut p = Lookahead::<N>::new(&MachineConfig::STRING_ART);
    let mut at = [0i32; AXES];
    for op in ops {
        match op {
            Op::Push(d, feed) => {
                if p.is_full() {
                    p.take_speeds();
                }
                // Onward: the move's direction mostly keeps the last one's.
                at = core::array::from_fn(|i| at[i] + d[i] + 300);
                p.push(at, *feed).unwrap();
            }
            Op::Take => {
                p.take_speeds();
            }
            Op::LimitEntry(v) => p.limit_entry(*v),
            Op::Overrides(f) => p.set_overrides(Overrides {
                feed: *f,
                rapid: 100,
            }),
        }
        let entries: Vec<u32> = (0..p.len)
            .map(|i| p.blocks[(p.head + i) % N].entry_sqr)
            .collect();
        prop_assert_eq!(entries, replanned(&p), "after {:?}", op);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// Planning only the blocks not yet final gives what planning the
    /// whole queue gives, at the firmware's depth and at Grbl-Mega's.
    #[test]
    fn planning_from_the_last_final_block_is_planning_all(ops in ops()) {
        incremental_matches_full::<PLANNER_BLOCKS>(&ops)?;
        incremental_matches_full::<36>(&ops)?;
    }
}
