//! Random event sequences: the job never panics, never overflows its
//! action list, and never moves the machine outside drilling and winding.

use super::*;
use proptest::prelude::*;

/// An event, or the firmware taking the steps of a batch (or of part of
/// one) and reporting them done.
#[derive(Clone, Copy, Debug)]
enum Op {
    Send(usize),
    Batch(u8),
}

/// Four nails and three wraps: a run can go through a whole job.
const SMALL: Params = Params {
    shape: 0,
    nails: 4,
    radius_um: 402_000,
};

fn event(k: usize, nail: u16) -> Event<'static> {
    let button = Button::ALL[k % 4];
    match k {
        0 => Event::PowerOn,
        1 => Event::CardInserted,
        2 => Event::CardRemoved,
        3 => valid(SMALL, 3),
        4 => valid(SMALL, 6),
        5 => Event::FilesInvalid,
        6 => Event::MotionDone,
        7 => LONG_GREEN,
        8 => Event::Resume,
        9 => Event::Nail(nail),
        10 => Event::PatternLost,
        27 => Event::Abort,
        29 => Event::CardUnusable,
        28 => Event::Saved(super::resume::saved(
            SMALL,
            3,
            Phase::Winding,
            nail as u32 % 8,
            nail % 4,
        )),
        11..=14 => Event::Button(ButtonEvent::Pressed(button)),
        15..=18 => Event::Button(ButtonEvent::Released {
            button,
            held_ms: 100,
        }),
        19..=22 => Event::Button(ButtonEvent::Released {
            button,
            held_ms: 2500,
        }),
        _ => Event::Button(ButtonEvent::LongPress(button)),
    }
}

/// Weighted so that runs get through reading into drilling and winding:
/// resets are rare, green and the motion loop common.
fn ops() -> impl Strategy<Value = Vec<(Op, u16)>> {
    let op = prop_oneof![
        1 => (0usize..30).prop_map(Op::Send),
        2 => Just(Op::Send(1)),
        2 => Just(Op::Send(3)),
        4 => Just(Op::Send(15)),
        6 => Just(Op::Send(6)),
        4 => Just(Op::Send(9)),
        12 => (1u8..8).prop_map(Op::Batch),
    ];
    proptest::collection::vec((op, 0u16..5), 0..600)
}

/// Sends one event and checks what it asks for.
fn send(job: &mut Job, e: Event) -> Result<(), TestCaseError> {
    let before = job.state();
    let actions = job.on(e, 0);
    let after = job.state();
    for a in &actions {
        match a {
            Action::NextMoves => prop_assert!(after.is_running(), "{:?} -> {:?}", before, after),
            Action::SetZero(_) => prop_assert!(
                matches!(
                    before,
                    State::PrepDrill | State::WaitingForNails | State::PrepResume(_)
                ),
                "zero in {:?}",
                before
            ),
            Action::DriversOn(_) => prop_assert!(
                !matches!(
                    after,
                    State::WaitingForCard | State::Reading | State::BadFiles | State::End
                ),
                "drivers on in {:?}",
                after
            ),
            Action::OpenPattern => prop_assert!(matches!(
                after,
                State::Winding | State::Paused(Phase::Winding)
            )),
            _ => {}
        }
    }
    Ok(())
}

proptest! {
    #[test]
    fn motion_only_while_drilling_or_winding(ops in ops()) {
        let mut job = Job::new();
        for (op, nail) in ops {
            match op {
                Op::Batch(n) => {
                    for _ in 0..n {
                        if job.next_step().is_some() {
                            prop_assert!(job.state().is_running(), "a step in {:?}", job.state());
                        }
                    }
                    send(&mut job, Event::MotionDone)?;
                }
                Op::Send(k) => send(&mut job, event(k, nail))?,
            }
            if !job.state().is_running() {
                prop_assert_eq!(job.next_step(), None);
            }
        }
    }
}
