//! Machine time of a G-code stream worked out on the host, with the
//! firmware's own parser, executor, kinematics and planner: what a
//! sender needs for an honest ETA. The executor carries each line out
//! against a [`MachineIo`] whose planner is the firmware's and whose
//! clock counts the planned blocks' time: a block's time is counted when
//! the planner hands it on (when it is full, or when a line waits for the
//! motion to end), with the exit speed the lines after it allow. Dwells
//! and the pen's settle time count once the machine stands.

use super::{coords, Allowed, Env, Exact, Interpreter, MachineIo, Progress, Wait};
use crate::config::MachineConfig;
use crate::coords::CoordData;
use crate::gcode::{Input, Parser};
use crate::kinematics::{AnyKinematics, Piece, Steps};
use crate::planner::{Feed, Lookahead, PLANNER_BLOCKS};
use crate::segment::SUBTICKS_PER_S;

/// Runs a stream of G-code through the firmware's parser, executor and
/// planner, the planner `N` blocks deep (the firmware's unless asked:
/// [`GcodeTime::with_depth`]).
pub struct GcodeTime<const N: usize = PLANNER_BLOCKS> {
    parser: Parser,
    interp: Interpreter,
    kin: AnyKinematics,
    config: MachineConfig,
    machine: Timed<N>,
    /// Lines read, and lines refused (they move nothing, as on the machine).
    pub lines: u32,
    pub refused: u32,
}

/// The machine as the estimate sees it: the planner, a clock of
/// sub-ticks, the pen's angle, the coordinate data.
struct Timed<const N: usize> {
    planner: Lookahead<N>,
    /// Sub-ticks of motion and waiting counted so far.
    subticks: u64,
    pen: Option<u8>,
    coords: CoordData,
}

impl<const N: usize> Timed<N> {
    fn take(&mut self) {
        if let Some(p) = self.planner.take() {
            self.subticks += p.profile.time(p.profile.events());
        }
    }

    fn settle(&mut self) {
        while !self.planner.is_idle() {
            self.take();
        }
    }
}

impl<const N: usize> MachineIo for Timed<N> {
    fn coord(&self, index: u8) -> Exact {
        coords::stored(&self.coords, index)
    }

    fn set_coord(&mut self, index: u8, value: &Exact) {
        coords::store(&mut self.coords, index, value);
    }

    fn room(&mut self, _piece: bool) -> Option<Wait> {
        // A full planner hands its oldest block on (its time counted).
        if self.planner.is_full() {
            self.take();
        }
        None
    }

    fn steps(&self) -> Steps {
        self.planner.position()
    }

    fn queue(&mut self, steps: &Steps, feed: Feed) -> bool {
        self.planner.push(*steps, feed).is_ok()
    }

    fn queue_piece(&mut self, piece: &Piece, feed: Feed) -> bool {
        self.planner.push_piece(piece, feed).is_ok()
    }

    fn idle(&mut self) -> bool {
        self.settle();
        true
    }

    fn pen(&mut self, deg: u8) -> bool {
        self.pen.replace(deg) != Some(deg)
    }

    fn drivers(&mut self, _on: bool) {}

    fn idle_delay(&mut self, _ms: u32) {}

    fn pause(&mut self) {}

    fn report_position(&mut self) {}

    fn program_end(&mut self) {}

    fn millis(&self) -> u32 {
        (self.subticks * 1000 / SUBTICKS_PER_S) as u32
    }
}

impl GcodeTime {
    /// `None` when the configuration's kinematics cannot be made.
    pub fn new(config: &MachineConfig) -> Option<Self> {
        Self::with_depth(config)
    }
}

impl<const N: usize> GcodeTime<N> {
    /// [`GcodeTime::new`] with a planner of `N` blocks.
    pub fn with_depth(config: &MachineConfig) -> Option<Self> {
        Some(GcodeTime {
            parser: Parser::new(),
            interp: Interpreter::new(),
            kin: AnyKinematics::of(config).ok()?,
            config: *config,
            machine: Timed {
                planner: Lookahead::new(config),
                subticks: 0,
                pen: None,
                coords: CoordData::ZERO,
            },
            lines: 0,
            refused: 0,
        })
    }

    /// Feeds the stream's bytes; each line is carried out when it ends.
    pub fn push(&mut self, bytes: &[u8]) {
        for &b in bytes {
            let (block, jog) = match self.parser.push(b) {
                None => continue,
                Some(Ok(Input::Block(block))) => (block, false),
                Some(Ok(Input::Jog(block))) => (block, true),
                Some(Ok(_)) => {
                    self.lines += 1;
                    continue;
                }
                Some(Err(_)) => {
                    self.lines += 1;
                    self.refused += 1;
                    continue;
                }
            };
            self.lines += 1;
            let env = Env {
                kin: &self.kin,
                cfg: &self.config,
                allowed: Allowed::ALL,
            };
            if self
                .interp
                .accept(&block, jog, &env, &mut self.machine)
                .is_err()
            {
                self.refused += 1;
                continue;
            }
            loop {
                match self.interp.run(&env, &mut self.machine) {
                    Progress::Done => break,
                    Progress::Wait(Wait::Ms(ms)) => {
                        self.machine.subticks += ms as u64 * SUBTICKS_PER_S / 1000
                    }
                    // The machine's `idle` and `room` make their own way.
                    Progress::Wait(_) => {}
                }
            }
        }
    }

    /// Seconds counted so far: the blocks the planner has handed on.
    pub fn seconds(&self) -> f64 {
        self.machine.subticks as f64 / SUBTICKS_PER_S as f64
    }

    /// The whole stream's time: every block still planned run out.
    pub fn finish(mut self) -> f64 {
        // The tiny moves joined last.
        self.interp.flush_soon();
        let env = Env {
            kin: &self.kin,
            cfg: &self.config,
            allowed: Allowed::ALL,
        };
        while self.interp.run(&env, &mut self.machine) != Progress::Done {}
        self.machine.settle();
        self.seconds()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::Machine;

    fn time_of(machine: Machine, gcode: &str) -> (f64, u32) {
        let mut t = GcodeTime::new(&MachineConfig::defaults(machine)).unwrap();
        t.push(gcode.as_bytes());
        let refused = t.refused;
        (t.finish(), refused)
    }

    /// A long straight move at a feed the flatbed reaches: its length over
    /// the feed, plus what the ramps lose (each takes v/a at half speed).
    #[test]
    fn a_long_move_takes_its_length_over_the_feed() {
        // 100 mm at 1200 mm/min (20 mm/s): 5 s; 4000 steps/s² at 40 steps/mm
        // is 100 mm/s², so the two ramps lose v/a = 0.2 s.
        let (s, refused) = time_of(Machine::Flatbed, "G21 G90\nG1 X100 F1200\n");
        assert_eq!(refused, 0);
        assert!((s - 5.2).abs() < 0.002, "{s}");
    }

    #[test]
    fn dwells_count_and_refused_lines_do_not_move() {
        let (plain, _) = time_of(Machine::Flatbed, "G1 X10 F600\n");
        let (dwelt, _) = time_of(Machine::Flatbed, "G1 X10 F600\nG4 P500\n");
        // The flatbed reads G4 P in ms (dwell_p_ms).
        assert!((dwelt - plain - 0.5).abs() < 1e-6, "{plain} {dwelt}");
        let (bad, refused) = time_of(Machine::Flatbed, "G1 X10 F600\nG1 X500\nG5 X3\n");
        assert_eq!(refused, 2);
        assert!((bad - plain).abs() < 1e-9);
    }

    /// A circle of arcs and a SCARA's straight line (cut in pieces and
    /// run through its inverse kinematics) both take time, and a faster
    /// feed takes less.
    #[test]
    fn arcs_and_arm_moves_are_timed() {
        let circle = |f: u32| std::format!("G1 X20 Y20 F{f}\nG2 X20 Y20 I10 J0\n");
        let (slow, r0) = time_of(Machine::Flatbed, &circle(300));
        let (fast, r1) = time_of(Machine::Flatbed, &circle(1200));
        assert_eq!((r0, r1), (0, 0));
        assert!(fast < slow && fast > 0.5, "{fast} {slow}");
        let (arm, r) = time_of(Machine::Scara, "G1 X90 Y140 F600\nG1 X60 Y140\n");
        assert_eq!(r, 0);
        assert!(arm > 3.0, "{arm}");
    }

    /// Tiny moves straight on are bound by the look-ahead: the block
    /// handed on must leave at a speed that stops within the others
    /// planned, so the cruise speed² grows with the depth: v² = 2·a·(N −
    /// 1)·length, far below F3000's 50 mm/s for 0.1 mm on the flatbed.
    /// (Each line's feed differs from the last's: none are joined.)
    #[test]
    fn a_deeper_planner_runs_tiny_moves_faster() {
        fn seconds<const N: usize>() -> f64 {
            let cfg = MachineConfig::defaults(Machine::Flatbed);
            let mut t = GcodeTime::<N>::with_depth(&cfg).unwrap();
            t.push(b"G21 G90\nG1 X0 Y10 F3000\nG4 P0\n");
            let before = t.seconds();
            for k in 1..=1000 {
                let feed = 3000 - k % 2;
                t.push(std::format!("G1 Y{} F{feed}\n", 10.0 + k as f64 * 0.1).as_bytes());
            }
            assert_eq!(t.refused, 0);
            t.finish() - before
        }
        // 100 mm at 100 mm/s²: the cruise, and a ramp at each end that
        // loses v/a.
        let ideal = |n: usize| {
            let v = (2.0 * 100.0 * (n - 1) as f64 * 0.1).sqrt();
            100.0 / v + v / 100.0
        };
        for (s, n) in [
            (seconds::<PLANNER_BLOCKS>(), PLANNER_BLOCKS),
            (seconds::<36>(), 36),
        ] {
            assert!((s / ideal(n) - 1.0).abs() < 0.02, "{n} blocks: {s} s");
        }
    }

    /// The same tiny moves at one feed are joined (under 2 mm each): the
    /// look-ahead reaches 20 mm, and they run at the feed but for the
    /// ramps (100 mm at 50 mm/s, and v/a lost at the ends).
    #[test]
    fn joined_tiny_moves_run_at_the_feed() {
        let cfg = MachineConfig::defaults(Machine::Flatbed);
        let mut t = GcodeTime::new(&cfg).unwrap();
        t.push(b"G21 G90\nG1 X0 Y10 F3000\nG4 P0\n");
        let before = t.seconds();
        for k in 1..=1000 {
            t.push(std::format!("G1 Y{}\n", 10.0 + k as f64 * 0.1).as_bytes());
        }
        let s = t.finish() - before;
        assert!(
            (s / (100.0 / 50.0 + 50.0 / 100.0) - 1.0).abs() < 0.02,
            "{s} s"
        );
    }

    /// On the arm and the whiteboard `F` is the pen's speed: a line takes
    /// the pen's trapezoid (its feed, `pen_accel`), as on the flatbed.
    #[test]
    fn the_pens_lines_take_the_pens_trapezoid() {
        for (machine, from, to, feed) in [
            (Machine::Scara, (80.0, 150.0), (80.0, 190.0), 600.0),
            (Machine::Scara, (60.0, 200.0), (100.0, 200.0), 600.0),
            (Machine::Whiteboard, (0.0, 0.0), (-200.0, 150.0), 3000.0),
        ] {
            let cfg = MachineConfig::defaults(machine);
            let mut t = GcodeTime::new(&cfg).unwrap();
            t.push(std::format!("G0 X{} Y{}\nG4 P0\n", from.0, from.1).as_bytes());
            let before = t.seconds();
            t.push(std::format!("G1 X{} Y{} F{feed}\n", to.0, to.1).as_bytes());
            assert_eq!(t.refused, 0);
            let s = t.finish() - before;
            let length = f64::hypot(to.0 - from.0, to.1 - from.1);
            let (v, a) = (feed / 60.0, cfg.pen_accel as f64);
            let ideal = match v * v / a >= length {
                true => 2.0 * (length / a).sqrt(),
                false => v / a + length / v,
            };
            assert!(
                (s / ideal - 1.0).abs() < 0.002,
                "{machine:?}: {s} s, not {ideal}"
            );
        }
    }
}
