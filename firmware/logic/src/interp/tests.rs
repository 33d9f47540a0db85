use super::*;
use crate::gcode::{Input, Parser};
use crate::kinematics::Linear;
use std::vec::Vec;

const CFG: MachineConfig = MachineConfig::STRING_ART;
const FREE: Allowed = Allowed {
    motion: true,
    position_known: true,
};

fn line(text: &str) -> Line {
    let mut p = Parser::new();
    let out: Vec<_> = text
        .bytes()
        .chain([b'\n'])
        .filter_map(|b| p.push(b))
        .collect();
    match out.as_slice() {
        [Ok(Input::Line(l))] => *l,
        other => panic!("{text:?}: {other:?}"),
    }
}

/// Plans `text` with `allowed` and commits it when it is good.
fn run(i: &mut Interpreter, text: &str, allowed: Allowed) -> Result<Order, ErrorKind> {
    let kin = Linear::cylindrical(&CFG);
    let planned = i.plan(&line(text), &kin, &CFG, allowed)?;
    i.commit(planned);
    Ok(planned.order)
}

fn steps(order: Result<Order, ErrorKind>) -> Steps {
    match order {
        Ok(Order::Move { steps, .. }) | Ok(Order::SetPosition { steps }) => steps,
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_refused_line_changes_no_modal_state() {
    let mut i = Interpreter::new();
    assert_eq!(
        run(&mut i, "G91 G1 X1", FREE),
        Err(ErrorKind::UndefinedFeedRate)
    );
    // Still G90 G0: an absolute rapid move.
    let order = run(&mut i, "X5", FREE);
    assert_eq!(
        order.map(|o| matches!(
            o,
            Order::Move {
                feed: Feed::Rapid,
                ..
            }
        )),
        Ok(true)
    );
    assert_eq!(steps(Ok(order.unwrap()))[1], 160);
    // A feed below the minimum is refused and the old one stays.
    run(&mut i, "G1 F600", FREE).unwrap();
    assert_eq!(run(&mut i, "G1 X1 F5", FREE), Err(ErrorKind::FeedTooLow));
    let order = run(&mut i, "X6", FREE).unwrap();
    assert!(matches!(
        order,
        Order::Move {
            feed: Feed::PerMinute(Milli(600_000)),
            ..
        }
    ));
}

#[test]
fn planned_twice_committed_once_is_one_move() {
    // A line waiting for planner room is planned again: only the commit
    // moves the commanded position.
    let kin = Linear::cylindrical(&CFG);
    let mut i = Interpreter::new();
    run(&mut i, "G91", FREE).unwrap();
    let l = line("G0 C10");
    let first = i.plan(&l, &kin, &CFG, FREE).unwrap();
    let again = i.plan(&l, &kin, &CFG, FREE).unwrap();
    assert_eq!(first, again);
    i.commit(again);
    assert_eq!(i.target()[0], Milli(10_000));
}

#[test]
fn relative_moves_never_drift() {
    let mut i = Interpreter::new();
    run(&mut i, "G91 G1 F60000", FREE).unwrap();
    let mut last = [0; 4];
    for _ in 0..360 {
        last = steps(run(&mut i, "C1", FREE));
    }
    assert_eq!(last[0], 9600, "a whole turn, to the step");
    // 1000 × 0.001 mm on the radial axis (32 steps/mm): 32 steps exactly.
    for _ in 0..1000 {
        last = steps(run(&mut i, "X0.001", FREE));
    }
    assert_eq!(last[1], 32);
}

#[test]
fn soft_limits_refuse_before_anything_and_keep_the_target() {
    let mut i = Interpreter::new();
    assert_eq!(run(&mut i, "G0 X31", FREE), Err(ErrorKind::TravelExceeded));
    assert_eq!(
        run(&mut i, "G0 Z-30.001", FREE),
        Err(ErrorKind::TravelExceeded)
    );
    assert_eq!(i.target(), [Milli::ZERO; 4]);
    // The base turns freely.
    assert_eq!(steps(run(&mut i, "G0 C7200", FREE))[0], 192_000);
    // G92 moves the zero the limits count from.
    run(&mut i, "G92 X-440", FREE).unwrap();
    assert_eq!(steps(run(&mut i, "G0 X30", FREE))[1], 960);
}

#[test]
fn a_job_or_a_lost_position_refuses_what_would_move() {
    let mut i = Interpreter::new();
    let job = Allowed {
        motion: false,
        ..FREE
    };
    for text in ["G0 C1", "X1", "M17", "M18", "G92 C0"] {
        assert_eq!(
            run(&mut i, text, job),
            Err(ErrorKind::JobOwnsMotion),
            "{text}"
        );
    }
    assert_eq!(run(&mut i, "M114", job), Ok(Order::ReportPosition));
    assert_eq!(run(&mut i, "M400", job), Ok(Order::WaitIdle));
    let lost = Allowed {
        position_known: false,
        ..FREE
    };
    assert_eq!(run(&mut i, "G0 C1", lost), Err(ErrorKind::Locked));
    assert!(matches!(
        run(&mut i, "G92 C0", lost),
        Ok(Order::SetPosition { .. })
    ));
}

#[test]
fn reset_restores_the_modes_and_keeps_the_position() {
    let mut i = Interpreter::new();
    run(&mut i, "G91 G1 F100 C5", FREE).unwrap();
    i.reset();
    assert_eq!(i.target()[0], Milli(5_000));
    // G90 G0 again: an absolute rapid.
    assert!(matches!(
        run(&mut i, "C1", FREE),
        Ok(Order::Move { feed: Feed::Rapid, steps }) if steps[0] == 27
    ));
}

#[test]
fn dwell_and_drivers() {
    let mut i = Interpreter::new();
    assert_eq!(run(&mut i, "G4 P1.5", FREE), Ok(Order::Dwell { ms: 1500 }));
    assert_eq!(run(&mut i, "M17", FREE), Ok(Order::Drivers { on: true }));
    assert_eq!(run(&mut i, "M84", FREE), Ok(Order::Drivers { on: false }));
    assert_eq!(run(&mut i, "G91", FREE), Ok(Order::None));
}
