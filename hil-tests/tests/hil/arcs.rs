//! `G2`/`G3` arcs, checked from the pulses alone. On the
//! string-art machine the plane with two linear axes is `G18`: the drill
//! (Z) and the radial carriage (X).

use hil_tests::sim::Sim;
use hil_tests::{assert_ram_budget, boot_machine, log_tail, send_ok, track};
use std::time::Duration;

fn send(sim: &mut Sim, line: &str) {
    send_ok(sim, line, Duration::from_secs(30));
}

/// Steps per mm: radial (X) 32, drill (Z) 1600 per 12 mm.
const X_STEPS: f64 = 32.0;
const Z_STEPS: f64 = 1600.0 / 12.0;

/// Every point of the path since `from` lies on the circle of radius 5 mm
/// round X5 Z0 — inside by at most the chord tolerance (0.01 mm), and off
/// by at most one step of each axis — and the machine never stopped
/// between chords. Returns the lowest Z reached, mm.
fn on_the_circle(path: &[(u64, [i64; 3])]) -> f64 {
    let slack = (1.0 / X_STEPS).hypot(1.0 / Z_STEPS);
    let mut lowest = f64::MAX;
    for (_, [_, x, z]) in path {
        let (x, z) = (*x as f64 / X_STEPS, *z as f64 / Z_STEPS);
        let d = (x - 5.0).hypot(z);
        assert!(
            d >= 5.0 - 0.010 - slack && d <= 5.0 + slack,
            "X{x:.4} Z{z:.4} is {d:.4} mm from the centre"
        );
        lowest = lowest.min(z);
    }
    // At 10 mm/s a step comes at least every 4 ms on the circle; a stop
    // and restart between chords would take ~60 ms for its first step.
    let inner = &path[path.len() / 20..path.len() * 19 / 20];
    let gap = inner.windows(2).map(|w| w[1].0 - w[0].0).max().unwrap();
    assert!(gap < 16_000 * 10, "{} ms without a step", gap / 16_000);
    lowest
}

#[test]
fn arcs_in_the_zx_plane_are_drawn_on_their_circle_and_end_exactly() {
    let mut sim = boot_machine();
    send(&mut sim, "M17");
    let mut done = 0;
    let mut arc = |sim: &mut Sim, line: &str, end: [i64; 2]| {
        send(sim, line);
        send(sim, "M400");
        let path = track(sim);
        let last = path.last().unwrap().1;
        assert_eq!(
            [last[1], last[2]],
            end,
            "{line} ended off target:\n{}",
            log_tail(sim)
        );
        assert_eq!(last[0], 0, "the base never turned");
        let lowest = on_the_circle(&path[done..]);
        done = path.len();
        lowest
    };
    // Half a turn clockwise through Z-5 (G2 in ZX: Z right, X up).
    let lowest = arc(&mut sim, "G18 G2 X10 I5 F600", [320, 0]);
    assert!((lowest + 5.0).abs() < 0.05, "through Z{lowest}");
    // A whole turn, relative, counter-clockwise (an axis word in the plane
    // is required, as in Grbl: here X0).
    send(&mut sim, "G91");
    arc(&mut sim, "G3 X0 I-5", [320, 0]);
    // Three quarters the long way round (negative R), absolute again.
    send(&mut sim, "G90");
    arc(&mut sim, "G2 X5 Z-5 R-5", [160, -667]);
    eprintln!(
        "peak stack {} B at {:#x}",
        sim.peak_stack_bytes(),
        sim.peak_stack_pc()
    );
    assert_ram_budget(&sim);
}
