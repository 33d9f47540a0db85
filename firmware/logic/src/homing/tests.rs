use super::*;
use crate::machine::Machine;
use std::vec::Vec;

/// A flatbed whose X switch closes at or below step `switch` (None: no
/// switch; `stuck`: closed everywhere): runs homing, moving step by step.
/// Returns how it ended and where X stands, in steps from where it began.
fn home(switch: Option<i32>, stuck: bool) -> (Next, i32, Vec<Next>) {
    let mut cfg = MachineConfig::defaults(Machine::Flatbed);
    cfg.homing.axes = 1;
    let closed = |p: i32| stuck || switch.is_some_and(|s| p <= s);
    let mut homing = Homing::new(cfg.homing.axes);
    let (mut p, mut hit, mut seen) = (0, false, Vec::new());
    loop {
        let next = homing.next(&cfg, hit, closed(p));
        seen.push(next);
        hit = false;
        match next {
            Next::Move(leg) => {
                assert_eq!(leg.axis, 0);
                let dir = leg.steps.signum();
                for _ in 0..leg.steps.abs() {
                    if leg.until_closed && closed(p) {
                        hit = true;
                        break;
                    }
                    p += dir;
                }
                hit |= leg.until_closed && closed(p);
            }
            Next::Zero { .. } => {}
            end => return (end, p, seen),
        }
    }
}

#[test]
fn the_axis_ends_pulled_off_its_switch_at_its_travel_start() {
    // The switch 3 mm (120 steps) below where X began.
    let (end, p, seen) = home(Some(-120), false);
    assert_eq!(end, Next::Done);
    // 1 mm (40 steps at 0.025 mm) off the switch, and that is X1.000.
    assert_eq!(p, -120 + 40);
    assert!(seen.contains(&Next::Zero { axis: 0, steps: 40 }));
    // Seek fast, past the whole 140 mm travel; locate slowly.
    assert_eq!(
        seen[0],
        Next::Move(Leg {
            axis: 0,
            steps: -8400,
            rate: 1000,
            until_closed: true
        })
    );
    assert!(matches!(
        seen[2],
        Next::Move(Leg {
            rate: 100,
            until_closed: true,
            ..
        })
    ));
}

#[test]
fn a_missing_or_stuck_switch_fails_homing() {
    assert_eq!(home(None, false).0, Next::Failed(HomingError::NotFound));
    assert_eq!(home(None, true).0, Next::Failed(HomingError::Stuck));
}

#[test]
fn nothing_to_home_is_done_at_once() {
    let cfg = MachineConfig::defaults(Machine::Drum);
    assert_eq!(Homing::new(0).next(&cfg, false, false), Next::Done);
}
