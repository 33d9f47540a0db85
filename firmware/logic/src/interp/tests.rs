use super::*;
use crate::axis::AXES;
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
    i.commit(&planned);
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
fn a_word_of_no_channel_of_the_machine_is_refused() {
    let mut i = Interpreter::new();
    // The string-art machine's words are C, X and Z: a Y is no channel.
    assert_eq!(
        run(&mut i, "G91 G1 X1 Y2 F600", FREE),
        Err(ErrorKind::UnsupportedCommand)
    );
    // Nothing of the refused line was taken: still G90 G0.
    assert_eq!(steps(run(&mut i, "X1", FREE))[1], 32);
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
    i.commit(&again);
    assert_eq!(i.target()[0], Milli(10_000));
}

#[test]
fn relative_moves_never_drift() {
    let mut i = Interpreter::new();
    run(&mut i, "G91 G1 F60000", FREE).unwrap();
    let mut last = [0; AXES];
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
    assert_eq!(i.target(), [Milli::ZERO; AXES]);
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

/// The chord ends of an arc order, in milli-units of X and Z.
fn chords(order: Result<Order, ErrorKind>) -> Vec<(i32, i32)> {
    match order {
        Ok(Order::Path {
            path: Path::Arc(arc),
            feed,
        }) => {
            assert_eq!(feed, Feed::PerMinute(Milli(100_000)));
            arc.map(|p| (p[1].0, p[2].0)).collect()
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn arcs_in_the_zx_plane_end_exactly_and_stay_on_the_circle() {
    let mut i = Interpreter::new();
    // G18: Z then X, offsets K then I. Centre X5 Z0, radius 5, half a turn.
    let ends = chords(run(&mut i, "G18 G2 X10 I5 F100", FREE));
    assert_eq!(*ends.last().unwrap(), (10_000, 0));
    assert!(ends.len() > 10, "{} chords", ends.len());
    for (x, z) in &ends {
        let d = (((x - 5_000) as f64).powi(2) + (*z as f64).powi(2)).sqrt();
        assert!((d - 5_000.0).abs() <= 1.5, "{x} {z}");
    }
    // G2 in ZX (Z right, X up) is clockwise: from X0 through Z-5.
    assert!(ends.iter().all(|(_, z)| *z <= 0));
    assert_eq!(i.target()[1], Milli(10_000));
    // Modal: bare axis words continue the arc, here relative and back.
    run(&mut i, "G91", FREE).unwrap();
    let back = chords(run(&mut i, "X-10 R5", FREE));
    assert_eq!(*back.last().unwrap(), (0, 0));
    assert!(
        back.iter().all(|(_, z)| *z >= 0),
        "clockwise, the other half"
    );
}

#[test]
fn arcs_are_refused_whole_before_anything_moves() {
    let mut i = Interpreter::new();
    let refused = [
        // The circle passes X40, beyond the radial's travel (30).
        ("G18 G2 X0 I20 F100", ErrorKind::TravelExceeded),
        // A whole turn of radius 12.5 reaches Z+12.5, past the drill's
        // travel (12), though both its ends are inside.
        ("G18 G3 X0 I12.5 F100", ErrorKind::TravelExceeded),
        // The string-art machine has no Y: no arc in XY.
        ("G17 G2 X10 I5 F100", ErrorKind::ArcNoAxisInPlane),
        ("G18 G2 C10 I5 F100", ErrorKind::ArcNoAxisInPlane),
        ("G18 G2 X10 J5 F100", ErrorKind::ArcNoOffsetInPlane),
        ("G18 G2 X10 I4 F100", ErrorKind::InvalidTarget),
        ("G18 G2 X10 R4 F100", ErrorKind::ArcRadiusInvalid),
        ("G18 G2 X0 R4 F100", ErrorKind::InvalidTarget),
        ("G18 G2 X10 I5", ErrorKind::UndefinedFeedRate),
        ("I5 X10", ErrorKind::UnusedValueWords),
        ("G18 G2 I5 F100", ErrorKind::UnusedValueWords),
    ];
    for (text, kind) in refused {
        assert_eq!(run(&mut i, text, FREE).err(), Some(kind), "{text}");
        // No mode changed: a bare X is still an absolute rapid.
        assert_eq!(
            run(&mut i, "X1", FREE),
            Ok(Order::Move {
                steps: [0, 32, 0],
                feed: Feed::Rapid
            }),
            "after {text}"
        );
        run(&mut i, "X0", FREE).unwrap();
    }
    let job = Allowed {
        motion: false,
        ..FREE
    };
    let lost = Allowed {
        position_known: false,
        ..FREE
    };
    assert_eq!(
        run(&mut i, "G18 G2 X10 I5 F100", job).err(),
        Some(ErrorKind::JobOwnsMotion)
    );
    assert_eq!(
        run(&mut i, "G18 G2 X10 I5 F100", lost).err(),
        Some(ErrorKind::Locked)
    );
}

#[test]
fn a_full_circle_and_the_long_way_round() {
    let mut i = Interpreter::new();
    let circle = chords(run(&mut i, "G18 G3 X0 I5 F100", FREE));
    assert_eq!(*circle.last().unwrap(), (0, 0));
    let (min, max) = circle.iter().fold((i32::MAX, i32::MIN), |(a, b), (x, _)| {
        (a.min(*x), b.max(*x))
    });
    assert!((min, max) == (0, 10_000), "a whole turn: X {min}..{max}");
    // R negative: more than half a turn, so the path reaches past the
    // chord's far side.
    let short = chords(run(&mut i, "G2 X6 R5", FREE));
    run(&mut i, "G0 X0", FREE).unwrap();
    let long = chords(run(&mut i, "G2 X6 R-5", FREE));
    assert!(long.len() > short.len());
    assert!(long.iter().any(|(x, _)| *x > 6_000) && short.iter().all(|(x, _)| *x <= 6_000));
}

#[test]
fn straight_moves_of_an_arm_are_cut_into_pieces_that_it_reaches() {
    use crate::kinematics::AnyKinematics;
    use crate::machine::Machine;
    let cfg = MachineConfig::defaults(Machine::Scara);
    let kin = AnyKinematics::of(&cfg).unwrap();
    let mut i = Interpreter::new();
    i.resync(kin.forward(&[0; crate::axis::AXES]));
    let plan = |i: &mut Interpreter, text| {
        let planned = i.plan(&line(text), &kin, &cfg, FREE)?;
        i.commit(&planned);
        Ok::<_, ErrorKind>(planned.order)
    };
    plan(&mut i, "G0 X100 Y150").unwrap();
    let ends: Vec<Position> = match plan(&mut i, "G1 X130 Y110 F600") {
        Ok(Order::Path {
            path: Path::Line(line),
            ..
        }) => line.collect(),
        other => panic!("{other:?}"),
    };
    // 50 mm in pieces of at most 2 mm, on the line, the last one exact.
    assert_eq!(ends.len(), 25);
    assert_eq!(ends[11][..2], [Milli(114_400), Milli(130_800)]);
    assert_eq!(ends[24][..2], [Milli(130_000), Milli(110_000)]);
    // Out of the arms' reach (300 mm from the shoulder at 100, −56): refused
    // whole, nothing changes.
    assert_eq!(plan(&mut i, "G1 X100 Y250"), Err(ErrorKind::InvalidTarget));
    assert_eq!(i.target()[..2], [Milli(130_000), Milli(110_000)]);
}

#[test]
fn the_pen_of_a_plotter_answers_m3_m5_m300_and_z() {
    use crate::machine::Machine;
    let cfg = MachineConfig::defaults(Machine::Flatbed);
    let kin = crate::kinematics::AnyKinematics::of(&cfg).unwrap();
    let mut i = Interpreter::new();
    let mut plan = |text| {
        let planned = i.plan(&line(text), &kin, &cfg, FREE)?;
        i.commit(&planned);
        Ok::<_, ErrorKind>(planned.order)
    };
    let pen = |deg| Ok(Order::Pen { deg, ms: 150 });
    assert_eq!(plan("M3"), pen(30));
    assert_eq!(plan("M5"), pen(50));
    assert_eq!(plan("M300 S30"), pen(30));
    assert_eq!(plan("M300 S50"), pen(50));
    assert_eq!(plan("M3 S12.7"), pen(12));
    // Seed 002 and gcodetools: Z above 0 is up, 0 or below is down.
    assert_eq!(plan("G0 Z1"), pen(50));
    assert_eq!(plan("G1 Z-0.5 F100"), pen(30));
    assert_eq!(plan("G0 Z0"), pen(30));
    assert_eq!(plan("G1 X10 Z1"), Err(ErrorKind::PenWithMove));
    // Z drives no motor: X alone moves only X.
    assert_eq!(
        plan("G0 X1"),
        Ok(Order::Move {
            steps: [40, 0, 0],
            feed: Feed::Rapid
        })
    );
    assert_eq!(plan("M0"), Ok(Order::Pause));
    // The unicorn's `G4 P150` is 150 ms on a plotter.
    assert_eq!(plan("G4 P150"), Ok(Order::Dwell { ms: 150 }));
}

#[test]
fn the_string_art_machine_has_no_pen_and_dwells_in_seconds() {
    let mut i = Interpreter::new();
    assert_eq!(run(&mut i, "M3", FREE), Err(ErrorKind::UnsupportedCommand));
    assert_eq!(
        run(&mut i, "M300 S30", FREE),
        Err(ErrorKind::UnsupportedCommand)
    );
    assert_eq!(run(&mut i, "G4 P1.5", FREE), Ok(Order::Dwell { ms: 1500 }));
    // Z is the drill there.
    assert_eq!(steps(run(&mut i, "G0 Z1.5", FREE)), [0, 0, 200]);
}

#[test]
fn inches_are_converted_once_and_angles_stay_degrees() {
    let mut i = Interpreter::new();
    // 1 in = 25.4 mm = 812.8 → 813 radial steps; C stays 90°.
    assert_eq!(steps(run(&mut i, "G20 G0 X1 C90", FREE)), [2400, 813, 0]);
    // Modal: the next line is in inches too, from the absolute target.
    assert_eq!(steps(run(&mut i, "G91 X-0.5", FREE)), [2400, 406, 0]);
    assert_eq!(steps(run(&mut i, "G21 X-12.7", FREE)), [2400, 0, 0]);
    // F in inches per minute: 0.3 in/min = 7.62 mm/min, below the least.
    assert_eq!(
        run(&mut i, "G20 G1 X1 F0.3", FREE),
        Err(ErrorKind::FeedTooLow)
    );
}

/// `$G` in Grbl 1.1's words, after the lines that set each mode; a line
/// that fails changes none of it.
#[test]
fn parser_state_reports_the_modal_state_as_grbl() {
    let show = |i: &Interpreter, pen| crate::text::error::tests::show(&i.parser_state(pen));
    let mut i = Interpreter::new();
    assert_eq!(show(&i, false), "G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0");
    run(&mut i, "G91 G18 G1 X1 F500", FREE).unwrap();
    assert_eq!(show(&i, true), "G1 G54 G18 G21 G91 G94 M3 M9 T0 F500 S0");
    assert!(run(&mut i, "G90 G2 X5 I1", FREE).is_err());
    run(&mut i, "G20 G90", FREE).unwrap();
    // 500 mm/min is 19.7 inches a minute.
    assert_eq!(show(&i, false), "G1 G54 G18 G20 G90 G94 M5 M9 T0 F19 S0");
}

fn jog(text: &str) -> Line {
    let mut p = Parser::new();
    let out: Vec<_> = text
        .bytes()
        .chain([b'\n'])
        .filter_map(|b| p.push(b))
        .collect();
    match out.as_slice() {
        [Ok(Input::Jog(l))] => *l,
        other => panic!("{text:?}: {other:?}"),
    }
}

/// jogging.md: "The jog command ... G20, G21, G90, G91 ... only apply to
/// the jog and do not alter the g-code parser state"; "if soft limits
/// are enabled, jog commands beyond the travel are rejected with an
/// error" (15).
#[test]
fn a_jog_moves_and_keeps_the_modal_state_but_the_position() {
    let kin = Linear::cylindrical(&CFG);
    let mut i = Interpreter::new();
    run(&mut i, "G1 X-10 F300", FREE).unwrap();
    let before = i.parser_state(false);
    let planned = i
        .plan(&jog("$J=G91 G20 X-1 F10"), &kin, &CFG, FREE)
        .unwrap();
    // One inch further out at 10 in/min: 254 mm/min.
    assert_eq!(
        planned.order,
        Order::Move {
            // 35.4 mm at 32 steps/mm: 1132.8 steps, rounded once.
            steps: [0, -1133, 0],
            feed: Feed::PerMinute(Milli(254_000)),
        }
    );
    i.commit_jog(&planned);
    assert_eq!(i.parser_state(false), before, "G90 G21 G1 F300 stay");
    assert_eq!(i.target()[1], Milli(-35_400));
    // Beyond the radial travel (−450 mm): refused, nothing changes.
    assert_eq!(
        i.plan(&jog("$J=X-451 F100"), &kin, &CFG, FREE),
        Err(ErrorKind::TravelExceeded)
    );
    let locked = Allowed {
        position_known: false,
        ..FREE
    };
    assert_eq!(
        i.plan(&jog("$J=X-1 F100"), &kin, &CFG, locked),
        Err(ErrorKind::Locked)
    );
}
