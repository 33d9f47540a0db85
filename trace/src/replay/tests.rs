//! Replay of tiny synthetic traces.

use super::*;
use std::f64::consts::TAU;
use taut_logic::units::Milli;

const CONFIG: MachineConfig = MachineConfig::STRING_ART;

/// The sample card's board: hexagon, 24 nails, R = 200 mm (nails at 185 mm
/// on the vertices, 160.2 mm at the edge midpoints).
fn hexagon() -> Board {
    Board::new(6, 24, Milli(200_000)).unwrap()
}

/// Builds the machine's signals step by step, 1 µs apart.
struct Pulses {
    now: u64,
    pos: [i64; 3],
    /// step, dir, en of base, radial, drill.
    signals: Vec<Signal>,
}

fn signal(name: &str, initial: bool) -> Signal {
    Signal {
        name: name.to_string(),
        initial,
        changes: Vec::new(),
    }
}

impl Pulses {
    fn new() -> Pulses {
        let mut signals = Vec::new();
        for axis in ["base", "radial", "drill"] {
            for (part, initial) in [("step", false), ("dir", false), ("en", false)] {
                signals.push(signal(&format!("{axis}_{part}"), initial));
            }
        }
        signals.push(signal("btn_confirm", true));
        Pulses {
            now: 1_000,
            pos: [0; 3],
            signals,
        }
    }

    fn set(&mut self, i: usize, at: u64, high: bool) {
        let s = &mut self.signals[i];
        if s.changes.last().map_or(s.initial, |c| c.1) != high {
            s.changes.push((at, high));
        }
    }

    /// `axis` (0 base, 1 radial, 2 drill) to `target`, one step a µs.
    fn to(&mut self, axis: usize, target: i64) -> &mut Self {
        while self.pos[axis] != target {
            let up = target > self.pos[axis];
            self.set(3 * axis + 1, self.now - 500, up);
            self.set(3 * axis, self.now, true);
            self.set(3 * axis, self.now + 100, false);
            self.pos[axis] += if up { 1 } else { -1 };
            self.now += 1_000;
        }
        self
    }

    /// Base and radial stepping at the very same instants.
    fn both(&mut self, base: i64, radial: i64) -> &mut Self {
        let start = self.now;
        self.to(0, base);
        self.now = start;
        self.to(1, radial);
        self
    }

    fn enable(&mut self, axis: usize, on: bool) -> &mut Self {
        self.set(3 * axis + 2, self.now, on);
        self.now += 1_000;
        self
    }

    fn press(&mut self) -> &mut Self {
        self.set(9, self.now, false);
        self.set(9, self.now + 100_000, true);
        self.now += 200_000;
        self
    }

    fn job(&self) -> JobReplay {
        JobReplay::from_signals(&self.signals, hexagon(), &CONFIG).unwrap()
    }
}

#[test]
fn steps_are_counted_with_their_direction() {
    let mut p = Pulses::new();
    p.to(0, 5).to(0, 3).to(2, -2);
    let trace = Trace::from_signals(&p.signals, &CONFIG).unwrap();
    let base = trace.track(Axis::Base);
    assert_eq!(base.changes.len(), 7);
    assert_eq!(base.last(), 3);
    assert_eq!(trace.position(Axis::Base, 0), 0);
    // The first step's rising edge at 1 µs, the fifth at 5 µs.
    assert_eq!(trace.position(Axis::Base, 1_000), 1);
    assert_eq!(trace.position(Axis::Base, 5_999), 5);
    assert_eq!(trace.position(Axis::Base, 6_000), 4);
    assert_eq!(trace.position(Axis::Drill, u64::MAX), -2);
    assert_eq!(trace.position(Axis::Radial, u64::MAX), 0);
    // DIR low is the positive direction when the config says so.
    let [step, dir, ..] = &p.signals[..] else {
        unreachable!()
    };
    assert_eq!(Track::from_pulses(step, dir, false).last(), -3);
    // The events merge the axes in time order.
    let events = trace.events();
    assert_eq!(events.len(), 9);
    assert!(events.windows(2).all(|w| w[0].at_ns <= w[1].at_ns));
    assert_eq!(events.last().unwrap().axis, 2);
}

#[test]
fn drivers_and_buttons_over_time() {
    let mut p = Pulses::new();
    p.enable(0, true).press().enable(0, false).press();
    let trace = Trace::from_signals(&p.signals, &CONFIG).unwrap();
    assert_eq!(trace.drivers_on(1_500), [true, false, false]);
    assert_eq!(trace.drivers_on(trace.end_ns), [false; 3]);
    let presses = trace.presses("confirm");
    assert_eq!(presses, [2_000, 203_000]);
    assert_eq!(trace.releases("confirm"), [102_000, 303_000]);
    assert!(trace.driver_on(Axis::Base, presses[0]));
    assert!(!trace.driver_on(Axis::Base, presses[1]));
    assert!(trace.presses("zero_base").is_empty());
    // Active-low enables read the other way round.
    let mut low = CONFIG;
    low.axes[0].enable_active_high = false;
    let trace = Trace::from_signals(&p.signals, &low).unwrap();
    assert_eq!(trace.drivers_on(1_500), [false, false, false]);
    assert_eq!(trace.drivers_on(0), [true, false, false]);
}

#[test]
fn a_missing_signal_is_named() {
    let mut p = Pulses::new();
    p.signals.retain(|s| s.name != "radial_dir");
    let err = Trace::from_signals(&p.signals, &CONFIG).unwrap_err();
    assert_eq!(err, "no signal radial_dir in the trace");
}

#[test]
fn plunges_and_steps_below_the_surface() {
    let mut p = Pulses::new();
    // Raise, go over a spot, plunge, retract; then plunge and step the
    // base twice while below.
    p.to(2, -10).both(371, -1064).to(2, 10).to(2, -10);
    p.to(0, 800).to(2, 3).to(0, 802).to(2, 0).to(1, -1000);
    let job = p.job();
    let plunges = job.plunges();
    assert_eq!(plunges.len(), 2);
    assert_eq!((plunges[0].base, plunges[0].radial), (371, -1064));
    assert_eq!((plunges[1].base, plunges[1].radial), (800, -1064));
    let stray = job.moves_while_plunged();
    assert_eq!(stray.len(), 2);
    assert_eq!(
        (stray[0].axis, stray[0].pos, stray[0].drill),
        (Axis::Base, 801, 3)
    );
    assert_eq!(stray[1].pos, 802);
}

#[test]
fn the_ring_of_a_hexagon_and_of_a_circle() {
    let ring = Ring::new(&hexagon(), 9600);
    assert_eq!(ring.nails(), 24);
    assert!((ring.radius_at(0.0) - 185.0).abs() < 1e-3);
    // Edge midpoint (nail 2, 30°): the apothem 185·cos 30°.
    let apothem = 185.0 * (TAU / 12.0).cos();
    assert!((ring.radius_at(TAU / 12.0) - apothem).abs() < 1e-3);
    // Between nail 23 and nail 0, across the seam.
    assert!(ring.radius_at(-0.01) > apothem && ring.radius_at(TAU - 0.01) < 185.0);
    assert_eq!(ring.nail_steps(2).round(), 800.0);
    let circle = Ring::new(&Board::new(0, 250, Milli(402_000)).unwrap(), 9600);
    assert!((circle.radius_at(1.234) - 387.0).abs() < 1e-3);
    // Gaps: nail 1 is at 370.6 steps, nail 2 at 800.
    assert_eq!(ring.gap_at(585), Some(1));
    assert_eq!(ring.gap_at(372), Some(1));
    assert_eq!(ring.gap_at(371), None);
    assert_eq!(ring.gap_at(370), None);
    assert_eq!(ring.gap_at(369), Some(0));
    assert_eq!(ring.gap_at(9600 + 799), None);
    assert_eq!(ring.gap_at(-185), Some(23));
    // Nails passed, in the order of the rotation.
    assert_eq!(ring.nails_between(-185, 185), [0]);
    assert_eq!(ring.nails_between(585, 185), [1]);
    assert_eq!(ring.nails_between(9600 - 185, 9600 + 585), [0, 1]);
    assert_eq!(ring.nails_between(0, 371), [1]);
    assert!(ring.nails_between(372, 799).is_empty());
}

/// Winding from the zero pose (base 0, needle at the edge, outside):
/// entry, then wraps of nail 1 (from its gap before) and nail 0 (from its
/// gap after, backwards), with the radial inner/outer targets of the
/// sample board.
fn winding() -> Pulses {
    let (inner, outer) = (-1926, 448);
    let mut p = Pulses::new();
    p.press().press();
    p.to(0, 185).to(1, inner).to(0, 0);
    p.to(0, 185).to(1, outer).to(0, 585).to(1, inner);
    p.to(0, 185).to(1, outer).to(0, -185).to(1, inner);
    p
}

#[test]
fn wraps_are_read_from_the_crossings() {
    let job = winding().job();
    let c = job.crossings();
    let dirs: Vec<Direction> = c.iter().map(|c| c.direction).collect();
    use Direction::{In, Out};
    assert_eq!(dirs, [In, Out, In, Out, In]);
    let bases: Vec<i64> = c.iter().map(|c| c.base).collect();
    assert_eq!(bases, [185, 185, 585, 185, -185]);
    assert!((c[4].angle - (9600.0 - 185.0) / 9600.0 * TAU).abs() < 1e-9);
    assert_eq!(
        c.iter().map(|c| c.gap).collect::<Vec<_>>(),
        [Some(0), Some(0), Some(1), Some(0), Some(23)]
    );
    assert!(job.crossings_outside_gaps().is_empty());
    let wraps = job.wraps();
    assert_eq!(wraps.len(), 2);
    assert_eq!((wraps[0].out.base, wraps[0].back.base), (185, 585));
    assert_eq!(job.wrapped_nails(), [1, 0]);
    // A crossing is where the needle is first on the other side: within
    // one radial step (1/32 mm) inside the ring.
    let r = job.tool_radius(c[0].radial);
    assert!(r < job.ring.radius_at(c[0].angle) && r > job.ring.radius_at(c[0].angle) - 1.0 / 32.0);
}

#[test]
fn crossings_are_looked_for_from_the_second_press_of_green() {
    let mut p = Pulses::new();
    // Before winding: out and in at nail 1 itself, not counted.
    p.to(1, -1926).to(0, 371).to(1, 0).to(0, 0);
    p.press().press();
    p.to(0, 185).to(1, -1926);
    let job = p.job();
    assert_eq!(job.winding().0, job.trace.presses("confirm")[1]);
    assert_eq!(job.crossings().len(), 1);
    let mut all = p.job();
    all.set_winding(0, u64::MAX);
    // In at nail 0, out at nail 1, then the one in the gap.
    assert_eq!(all.crossings().len(), 3);
    assert_eq!(all.crossings_outside_gaps().len(), 2);
}

#[test]
fn a_crossing_at_a_nail_is_reported() {
    let mut p = winding();
    // Out a step past nail 2's angle (800), in at the gap after it.
    p.to(0, 801).to(1, 448).to(0, 1015).to(1, -1926);
    let job = p.job();
    let bad = job.crossings_outside_gaps();
    assert_eq!(bad.len(), 1);
    assert_eq!(
        (bad[0].direction, bad[0].base, bad[0].gap),
        (Direction::Out, 801, None)
    );
    // From a step past nail 2 to its gap after: nothing passed.
    assert_eq!(job.wrapped_nails(), [1, 0]);
}

#[test]
fn steps_at_the_same_instant_count_together() {
    let mut p = Pulses::new();
    // Needle inside at nail 1's gap after; then base and carriage step
    // together, ending outside beyond the gap before nail 2.
    p.to(1, -1926).to(0, 585).press().press().both(700, 448);
    let c = p.job().crossings();
    assert_eq!(c.len(), 1);
    assert_eq!(c[0].direction, Direction::Out);
    assert!(c[0].base <= 700 && c[0].radial <= 448);
}

#[test]
fn the_board_is_read_from_param_txt() {
    let b = board_from_param(b"tvar = 6\npocet_hrebiku = 24\npolomer_matrice = 20.0\n").unwrap();
    assert_eq!(b, hexagon());
    assert!(board_from_param(b"tvar = 6\n").is_err());
}
