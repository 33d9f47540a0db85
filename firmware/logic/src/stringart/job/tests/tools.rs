//! The operator's tools: parsed from `$` lines, refused while the job
//! moves, and what each does to the machine and the job.

use super::*;
use crate::checkpoint::Record;
use crate::stringart::job::tools::{parse, Tool, ToolError};

fn tool(b: &mut Bench, t: Tool) -> Vec<Action> {
    b.send(Event::Tool(t))
}

#[test]
fn tool_lines() {
    assert_eq!(parse("wrap_test", "5"), Some(Ok(Tool::WrapTest(5))));
    assert_eq!(parse("WRAP_STEP", "+1"), Some(Ok(Tool::Step)));
    assert_eq!(parse("wrap_jump", "1234"), Some(Ok(Tool::Jump(1234))));
    assert_eq!(parse("drift", "0"), Some(Ok(Tool::Drift(0))));
    assert_eq!(parse("wrap_test", "70000"), Some(Err(ToolError::BadValue)));
    assert_eq!(parse("wrap_step", "2"), Some(Err(ToolError::BadValue)));
    assert_eq!(parse("wrap_step", "-1"), Some(Ok(Tool::Back)));
    assert_eq!(parse("wrap_step", "-2"), Some(Err(ToolError::BadValue)));
    assert_eq!(parse("drift", "x"), Some(Err(ToolError::BadValue)));
    assert_eq!(parse("base_accel", "500"), None);
}

/// Drilled, nails in, zeroed: the job waits to wind.
fn waiting_for_nails() -> Bench {
    let mut b = Bench::new(HEX, &PATTERN);
    b.ready();
    b.green();
    b.run();
    assert_eq!(b.job.state(), State::WaitingForNails);
    b.steps.clear();
    b
}

#[test]
fn wrap_test_wraps_one_nail_from_the_zero_pose_and_back() {
    let mut b = waiting_for_nails();
    let k = 7;
    let go = tool(&mut b, Tool::WrapTest(k));
    assert_eq!(go, [Action::DriversOn(0b011), Action::NextMoves]);
    assert!(b.job.owns_motion());
    assert_eq!(
        tool(&mut b, Tool::WrapTest(2)),
        [Action::Log(Msg::ToolMoving)]
    );
    b.batch();
    // In through the gap before nail 7, the wrap, out at the edge, home.
    let mut w = BlendWinder::new(board(HEX), &CONFIG).unwrap();
    let mut expect: Vec<MachineStep> = (0..3).filter_map(|i| w.entry_step(Some(6), i)).collect();
    let wrap = w.wrap(k).unwrap();
    assert_eq!(wrap.gaps(), [6, 7], "out before nail 7, in after it");
    expect.extend(wrap);
    expect.push(MachineStep::to(Axis::Radial, 0));
    let n = expect.len();
    assert_eq!(b.steps[..n], expect[..]);
    assert_eq!(b.steps[n + 1..], []);
    let MachineStep::Move([Some(home), None, None]) = b.steps[n] else {
        panic!("{:?}", b.steps[n])
    };
    assert_eq!(home.rem_euclid(9600), 0);
    assert_eq!(b.job.state(), State::WaitingForNails);
    assert!(!b.job.owns_motion());
    assert!(b.actions.contains(&Action::Log(Msg::WrapTested)));
    assert_eq!(
        b.actions.last(),
        Some(&Action::Prompt(Prompt::StartWinding))
    );
    // No checkpoint: nothing of the job was done.
    assert!(b.saves.len() == 25, "{:?}", b.saves);
    // And the job winds as it would have.
    b.steps.clear();
    b.green();
    b.run();
    assert_eq!(b.steps, wound(HEX, &PATTERN));
}

#[test]
fn tools_are_refused_while_the_job_moves_or_out_of_place() {
    let mut b = Bench::new(HEX, &PATTERN);
    b.ready();
    assert_eq!(
        tool(&mut b, Tool::WrapTest(1)),
        [Action::Log(Msg::ToolNotNow)]
    );
    b.green();
    assert_eq!(tool(&mut b, Tool::Drift(0)), [Action::Log(Msg::ToolMoving)]);
    assert_eq!(tool(&mut b, Tool::Step), [Action::Log(Msg::ToolMoving)]);
    let mut b = waiting_for_nails();
    assert_eq!(
        tool(&mut b, Tool::WrapTest(24)),
        [Action::Log(Msg::ToolRange)]
    );
    assert_eq!(tool(&mut b, Tool::Jump(3)), [Action::Log(Msg::ToolNotNow)]);
}

/// Winding, paused after `wraps` wraps.
fn paused_after(wraps: usize) -> Bench {
    let mut b = waiting_for_nails();
    b.green();
    for _ in 0..=wraps {
        b.batch(); // the entry, then a wrap each
    }
    b.send(LONG_GREEN);
    assert_eq!(b.job.state(), State::Paused(Phase::Winding));
    // The next batch was asked for: none comes, the machine stands.
    b.batch();
    assert!(!b.job.owns_motion() || b.job.state() == State::Paused(Phase::Winding));
    b
}

/// Crossings of the band (the carriage's target changes): two a wrap.
fn crossings(steps: &[MachineStep]) -> usize {
    let mut radial = None;
    let mut n = 0;
    for s in steps {
        if let MachineStep::Move([_, Some(r), None]) = *s {
            n += radial.is_some_and(|was| was != r) as usize;
            radial = Some(r);
        }
    }
    n
}

#[test]
fn wrap_step_winds_one_wrap_and_pauses_again() {
    let mut b = paused_after(1);
    let before = b.steps.len();
    let go = tool(&mut b, Tool::Step);
    assert!(go.contains(&Action::NextMoves), "{go:?}");
    b.batch();
    assert_eq!(crossings(&b.steps[before - 1..]), 2, "one wrap");
    assert_eq!(b.job.state(), State::Paused(Phase::Winding));
    assert!(!b.batch(), "nothing more until green");
    b.green();
    b.run();
    assert_eq!(
        b.steps,
        [drilled(HEX), wound(HEX, &PATTERN)].concat()[drilled(HEX).len()..]
    );
}

#[test]
fn wrap_step_back_winds_the_last_wrap_again() {
    let mut b = paused_after(2);
    let go = tool(&mut b, Tool::Back);
    assert_eq!(go, [Action::OpenPattern, Action::NextMoves]);
    b.batch();
    assert!(b.actions.contains(&Action::Log(Msg::Jumped)));
    let before = b.steps.len();
    b.green();
    b.run();
    // Wraps 2 to 5: the second wound again, two crossings each.
    assert_eq!(crossings(&b.steps[before - 1..]), 8);
    // Before any wrap, nothing to step back to; not while drilling.
    let mut b = paused_after(0);
    assert_eq!(tool(&mut b, Tool::Back), [Action::Log(Msg::ToolRange)]);
}

#[test]
fn wrap_jump_goes_on_at_the_wrap_asked_with_its_checkpoint() {
    let mut b = paused_after(1);
    let saves = b.saves.len();
    let go = tool(&mut b, Tool::Jump(3));
    assert_eq!(go, [Action::OpenPattern, Action::NextMoves]);
    b.batch();
    // The record: 3 wraps done, the needle in through wrap 1's last gap.
    let Save::Record(r) = b.saves[saves] else {
        panic!("{:?}", b.saves)
    };
    assert_eq!(r.n, 6);
    assert_eq!(
        Some(&Save::Record(Record { n: 2, gap: r.gap })),
        b.saves.get(saves - 1)
    );
    assert!(b.actions.contains(&Action::Log(Msg::Jumped)));
    assert_eq!(b.job.state(), State::Paused(Phase::Winding));
    let before = b.steps.len();
    b.green();
    b.run();
    // Wraps 4 and 5 of the pattern, then the drivers off.
    assert_eq!(crossings(&b.steps[before - 1..]), 4);
    assert_eq!(b.job.state(), State::End);
}

#[test]
fn drift_goes_to_the_nail_says_where_and_comes_back() {
    let mut b = paused_after(2);
    let at = b.pos[0];
    tool(&mut b, Tool::Drift(0));
    b.batch();
    let there = b.pos[0];
    assert_eq!(there.rem_euclid(9600), 0, "nail 0's angle");
    assert!((there - at).abs() <= 4800, "the shorter way");
    let drift = b.actions.iter().find(|a| matches!(a, Action::Drift { .. }));
    assert_eq!(
        drift,
        Some(&Action::Drift {
            nail: 0,
            expected: there
        })
    );
    b.batch();
    assert_eq!(b.pos[0], at, "back where it was");
    assert!(b.actions.contains(&Action::Log(Msg::DriftChecked)));
    assert_eq!(b.job.state(), State::Paused(Phase::Winding));
}
