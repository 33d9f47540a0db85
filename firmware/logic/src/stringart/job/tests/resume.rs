//! Power cuts: the checkpoints a job writes, and the job resumed from
//! each of them on a fresh boot — nothing lost, nothing done twice.

use super::*;
use crate::axis::AXES;
use crate::checkpoint::{Header, Record, Saved};
use crate::geometry::StepScale;

/// The card identity of `valid(params, count)`.
fn card_id(params: Params, count: u32) -> CardId {
    match valid(params, count) {
        Event::FilesValid { id, .. } => id,
        _ => unreachable!(),
    }
}

/// What the EEPROM would hold with record `n` (0: none) of `phase`.
pub(super) fn saved(params: Params, count: u32, phase: Phase, n: u32, gap: u16) -> Saved {
    Saved {
        header: Header {
            seq: 7,
            phase: Some(phase),
            nails: params.nails,
            count,
            id: card_id(params, count),
        },
        last: (n > 0).then_some(Record { n, gap }),
    }
}

/// A whole job, recording the checkpoints and the pose at each.
fn whole_job(b: &mut Bench) -> Vec<(Save, [i32; AXES])> {
    b.ready();
    b.green();
    let mut saves = Vec::new();
    loop {
        b.feed();
        if !b.pulling {
            if matches!(b.job.state(), State::WaitingForNails) {
                b.green();
                continue;
            }
            break;
        }
        b.pulling = false;
        while let Some(step) = b.job.next_step() {
            match step {
                MachineStep::Move(t) => {
                    for (p, t) in b.pos.iter_mut().zip(t) {
                        *p = t.unwrap_or(*p);
                    }
                }
                MachineStep::Save(s) => saves.push((s, b.pos)),
                MachineStep::Mark(r) => saves.push((Save::Record(r), b.pos)),
                _ => {}
            }
            b.feed();
        }
        b.send(Event::MotionDone);
    }
    saves
}

#[test]
fn a_job_checkpoints_each_hole_and_twice_each_wrap() {
    let mut b = Bench::new(HEX, &PATTERN);
    let saves = whole_job(&mut b);
    assert_eq!(b.job.state(), State::End);
    let records = |from: usize, to: usize| -> Vec<u32> {
        saves[from..to]
            .iter()
            .map(|(s, _)| match s {
                Save::Record(r) => r.n,
                _ => panic!("{s:?}"),
            })
            .collect()
    };
    assert_eq!(saves[0].0, Save::Begin(Phase::Drilling));
    assert_eq!(records(1, 25), (1..=24).collect::<Vec<_>>());
    assert_eq!(saves[25].0, Save::Begin(Phase::Winding));
    assert_eq!(records(26, saves.len()), (1..=10).collect::<Vec<_>>());
    // Each hole's record with the drill down in it (after the dwell).
    for (s, pos) in &saves[1..25] {
        assert!(pos[Axis::Drill.index()] > 0, "{s:?} at {pos:?}");
    }
    // Each wrap's records, marked: the outward one with the needle inside
    // the ring (before the rotation to its gap), the inward one with the
    // needle outside, just through the outward one's gap.
    let scale = StepScale::from_config(&CONFIG);
    let board = board(HEX);
    let inner = saves.iter().map(|(_, p)| p[1]).min().unwrap();
    for (i, (s, pos)) in saves[26..].iter().enumerate() {
        let Save::Record(r) = s else { panic!() };
        let out = pos[Axis::Radial.index()] != inner;
        assert_eq!(out, i % 2 == 1, "{r:?} at {pos:?}");
        if out {
            let Save::Record(outward) = saves[26 + i - 1].0 else {
                panic!()
            };
            assert!(
                in_gap(&scale, &board, pos[0], outward.gap),
                "{r:?} at {pos:?}"
            );
        }
        let nail = PATTERN[i / 2];
        let beside = [(nail + 23) % 24, nail];
        assert!(beside.contains(&r.gap), "{r:?} beside nail {nail}");
    }
    // The end of the job forgets the checkpoint.
    let forget = b.actions.iter().position(|a| *a == Action::Forget);
    assert_eq!(forget, Some(b.actions.len() - 3), "{:?}", b.actions);
}

/// The order the feeder relies on: each record marked, then made
/// durable before the crossing of the band it is about, the only moves
/// between its mark and that along a circle (the base alone); the next
/// mark only after.
#[test]
fn each_record_is_durable_before_its_crossing() {
    let mut b = Bench::new(HEX, &PATTERN);
    b.ready();
    b.green();
    b.run();
    b.green();
    let (mut marked, mut durable, mut crossings) = (None, 0, 0);
    let mut at = b.pos;
    while b.pulling || b.job.state() == State::Winding {
        b.feed();
        b.pulling = false;
        while let Some(step) = b.job.next_step() {
            // The feeder writes the job's record of the mark, up to the
            // crossing: the mark's own.
            if marked.is_some() {
                assert_eq!(b.job.marked(), marked);
            }
            match step {
                MachineStep::Mark(r) => {
                    assert!(marked.is_none(), "two marks without a durable");
                    marked = Some(r);
                }
                MachineStep::Durable => {
                    assert!(marked.is_some(), "a durable without a mark");
                    (marked, durable) = (None, durable + 1);
                }
                MachineStep::Move(t) => {
                    let from = at;
                    for (p, t) in at.iter_mut().zip(t) {
                        *p = t.unwrap_or(*p);
                    }
                    let crossing = from[1] != at[1];
                    crossings += crossing as usize;
                    assert!(
                        !(marked.is_some() && crossing),
                        "a crossing before its record"
                    );
                }
                _ => {}
            }
            b.feed();
        }
        b.send(Event::MotionDone);
    }
    assert_eq!(b.job.state(), State::End);
    // The entry's crossing in, then two a wrap, each after its record.
    assert_eq!((durable, crossings), (10, 11));
}

/// Whether base position `base` lies strictly between the nails beside
/// the gap after nail `g`.
fn in_gap(scale: &StepScale, board: &Board, base: i32, g: u16) -> bool {
    let turn = scale.steps_per_turn;
    let at = |i: u16| scale.base_steps(board.nail(i % board.nails()).angle);
    let (lo, width) = (at(g), (at(g + 1) - at(g)).rem_euclid(turn));
    let d = (base - lo).rem_euclid(turn);
    0 < d && d < width
}

/// Boots a fresh job with `saved` in EEPROM and the same card, takes the
/// offer, zeroes the axes and runs to the end.
fn resumed(saved: Saved) -> (Bench, Vec<Action>) {
    let mut b = Bench::new(HEX, &PATTERN);
    b.sends(&[Event::PowerOn, Event::Saved(saved), Event::CardInserted]);
    let offer = b.send(valid(HEX, 5));
    assert_eq!(b.job.state(), State::Offer);
    assert_eq!(b.drivers, 0, "nothing powered before the operator says");
    let prep = b.green();
    assert_eq!(b.job.state(), State::PrepResume(saved.phase()));
    assert!(prep.contains(&Action::Prompt(Prompt::ZeroToResume)));
    // Not before every axis is zeroed again.
    assert_eq!(b.green(), [Action::Log(Msg::ZeroAll)]);
    for button in [Button::ZeroBase, Button::ZeroRadial] {
        b.sends(&short(button));
        b.sends(&short(button));
    }
    assert_eq!(b.green(), [Action::Log(Msg::ZeroAll)]);
    b.sends(&short(Button::ZeroDrill));
    assert_eq!(b.green(), [Action::Log(Msg::ZeroPending)]);
    b.sends(&short(Button::ZeroDrill));
    b.green();
    b.run();
    if b.job.state() == State::WaitingForNails {
        b.green();
        b.run();
    }
    assert_eq!(b.job.state(), State::End);
    (b, offer)
}

#[test]
fn drilling_resumes_with_the_drill_raised_at_the_hole_after_the_record() {
    let plunges = |steps: &[MachineStep]| -> Vec<i32> {
        let mut base = 0;
        let mut out = Vec::new();
        for s in steps {
            if let MachineStep::Move(t) = s {
                base = t[0].unwrap_or(base);
                if t[2].is_some_and(|d| d > 0) {
                    out.push(base.rem_euclid(9600));
                }
            }
        }
        out
    };
    let all = plunges(&drilled(HEX));
    for n in 0..=24 {
        let (b, offer) = resumed(saved(HEX, 5, Phase::Drilling, n, 0));
        let next = (n + 1).min(24);
        assert_eq!(
            offer[offer.len() - 1],
            Action::Offer {
                phase: Phase::Drilling,
                next,
                total: 24
            }
        );
        // The drill goes up first, then the holes from n on, once each.
        // 2 mm above the surface along the tilted axis.
        assert_eq!(b.steps[0], MachineStep::to(Axis::Drill, -277), "from {n}");
        let drilling_end = b.steps.len() - wound(HEX, &PATTERN).len();
        assert_eq!(
            plunges(&b.steps[..drilling_end]),
            all[n as usize..],
            "from {n}"
        );
        // No header again: the phase's records go on from n.
        let first = b.saves.iter().find_map(|s| match s {
            Save::Record(r) => Some(r.n),
            _ => None,
        });
        if n < 24 {
            assert_eq!(first, Some(n + 1));
            assert_ne!(b.saves[0], Save::Begin(Phase::Drilling));
        }
        assert_eq!(b.actions.last(), Some(&Action::Prompt(Prompt::Finished)));
        assert!(b.actions.contains(&Action::Forget));
    }
}

#[test]
fn winding_resumes_through_the_gap_of_the_record() {
    let full = whole_job(&mut Bench::new(HEX, &PATTERN));
    let winding: Vec<Record> = full
        .iter()
        .skip_while(|(s, _)| *s != Save::Begin(Phase::Winding))
        .filter_map(|(s, _)| match s {
            Save::Record(r) => Some(*r),
            _ => None,
        })
        .collect();
    let scale = StepScale::from_config(&CONFIG);
    let board = board(HEX);
    // Needle moves out: from the inner radius to anywhere else.
    let outs = |steps: &[MachineStep]| {
        let radial: Vec<i32> = steps
            .iter()
            .filter_map(|s| match s {
                MachineStep::Move(t) => t[1],
                _ => None,
            })
            .collect();
        let inner = *radial.iter().min().unwrap();
        radial
            .windows(2)
            .filter(|w| w[0] == inner && w[1] != inner)
            .count()
    };
    for r in winding {
        let (b, offer) = resumed(saved(HEX, 5, Phase::Winding, r.n, r.gap));
        assert_eq!(
            offer.last(),
            Some(&Action::Offer {
                phase: Phase::Winding,
                next: (r.n / 2 + 1).min(5),
                total: 5
            })
        );
        // The pattern is read from its start, the wraps done passed over
        // (the count of wraps below).
        assert!(b.actions.contains(&Action::OpenPattern));
        // Entry: the drill's driver off, the base into the record's gap
        // (the needle outside), the needle in across it.
        assert_eq!(
            b.steps[0],
            MachineStep::Drivers {
                mask: 0b100,
                on: false
            }
        );
        let MachineStep::Move([Some(at), None, None]) = b.steps[1] else {
            panic!("{:?}", b.steps[1])
        };
        assert!(in_gap(&scale, &board, at, r.gap), "{at} for {r:?}");
        let MachineStep::Move([Some(at), Some(inner), None]) = b.steps[2] else {
            panic!("{:?}", b.steps[2])
        };
        assert!(in_gap(&scale, &board, at, r.gap) && inner < 0);
        // Then the wraps not yet wound, each out and back once.
        assert_eq!(outs(&b.steps), 5 - r.n as usize / 2, "from {r:?}");
        let ns: Vec<u32> = b
            .saves
            .iter()
            .map(|s| match s {
                Save::Record(r) => r.n,
                _ => panic!("{s:?}"),
            })
            .collect();
        // A wrap's first record comes again (the same bytes: nothing is
        // written) when the resume starts at its gap.
        let from = if r.n % 2 == 1 { r.n } else { r.n + 1 };
        assert_eq!(ns, (from..=10).collect::<Vec<_>>());
    }
    // With no record yet, the normal entry and the whole pattern.
    let (b, _) = resumed(saved(HEX, 5, Phase::Winding, 0, 0));
    assert_eq!(outs(&b.steps), 5);
    assert_eq!(b.steps, wound(HEX, &PATTERN));
}

#[test]
fn another_card_discards_the_checkpoint() {
    let mut b = Bench::new(HEX, &PATTERN);
    b.sends(&[
        Event::PowerOn,
        Event::Saved(saved(HEX, 5, Phase::Winding, 7, 3)),
        Event::CardInserted,
    ]);
    assert_eq!(
        b.send(valid_pattern(HEX, 5, 1)),
        [
            Action::Configure,
            Action::Log(Msg::SavedOtherCard),
            Action::Forget,
            Action::DriversOn(ALL),
            Action::Enter(State::PrepDrill),
            Action::Prompt(Prompt::StartDrilling)
        ]
    );
}

#[test]
fn green_held_at_the_offer_discards_and_a_pulled_card_keeps_it() {
    let mut b = Bench::new(HEX, &PATTERN);
    b.sends(&[
        Event::PowerOn,
        Event::Saved(saved(HEX, 5, Phase::Winding, 7, 3)),
        Event::CardInserted,
        valid(HEX, 5),
    ]);
    // The card out and back: offered again.
    b.send(Event::CardRemoved);
    assert_eq!(b.job.state(), State::WaitingForCard);
    b.send(Event::CardInserted);
    let again = b.send(valid(HEX, 5));
    assert_eq!(again[..2], [Action::Configure, Action::Enter(State::Offer)]);
    assert_eq!(
        b.send(LONG_GREEN),
        [
            Action::Forget,
            Action::Log(Msg::SavedDiscarded),
            Action::DriversOn(ALL),
            Action::Enter(State::PrepDrill),
            Action::Prompt(Prompt::StartDrilling)
        ]
    );
    // A new job from the start.
    b.green();
    b.run();
    assert_eq!(b.steps, drilled(HEX));
}
