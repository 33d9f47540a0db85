//! Machine time of a G-code stream worked out on the host, with the
//! firmware's own parser, interpreter, kinematics and planner: what a
//! sender needs for an honest ETA. Each line's moves go into the planner
//! as the console queues them (a path piece by piece); a block's time is
//! counted when the planner hands it on, with the exit speed the lines
//! after it allow, so a line's time is final once later lines are in.
//! Dwells, the pen's settle time and a homing cycle wait for the machine
//! to stand (homing's own moves are not counted: where the switch is, is
//! the machine's secret).

use super::{Allowed, Interpreter, Order};
use crate::config::MachineConfig;
use crate::gcode::{Input, Parser};
use crate::kinematics::AnyKinematics;
use crate::planner::{Feed, Planner};
use crate::segment::SUBTICKS_PER_S;

/// Runs a stream of G-code through the firmware's planner.
pub struct GcodeTime {
    parser: Parser,
    interp: Interpreter,
    kin: AnyKinematics,
    config: MachineConfig,
    planner: Planner,
    /// Sub-ticks of motion and waiting counted so far.
    subticks: u64,
    /// Lines read, and lines refused (they move nothing, as on the machine).
    pub lines: u32,
    pub refused: u32,
}

impl GcodeTime {
    /// `None` when the configuration's kinematics cannot be made.
    pub fn new(config: &MachineConfig) -> Option<Self> {
        Some(GcodeTime {
            parser: Parser::new(),
            interp: Interpreter::new(),
            kin: AnyKinematics::of(config).ok()?,
            config: *config,
            planner: Planner::new(config),
            subticks: 0,
            lines: 0,
            refused: 0,
        })
    }

    /// Feeds the stream's bytes; each line is carried out when it ends.
    pub fn push(&mut self, bytes: &[u8]) {
        for &b in bytes {
            match self.parser.push(b) {
                Some(Ok(Input::Line(line))) => {
                    self.lines += 1;
                    let allowed = Allowed {
                        motion: true,
                        position_known: true,
                    };
                    match self.interp.plan(&line, &self.kin, &self.config, allowed) {
                        Ok(planned) => {
                            self.interp.commit(&planned);
                            self.carry_out(planned.order);
                        }
                        Err(_) => self.refused += 1,
                    }
                }
                Some(Ok(_)) => self.lines += 1,
                Some(Err(_)) => {
                    self.lines += 1;
                    self.refused += 1;
                }
                None => {}
            }
        }
    }

    /// Seconds counted so far: the blocks the planner has handed on.
    pub fn seconds(&self) -> f64 {
        self.subticks as f64 / SUBTICKS_PER_S as f64
    }

    /// The whole stream's time: every block still planned run out.
    pub fn finish(mut self) -> f64 {
        self.settle();
        self.seconds()
    }

    fn carry_out(&mut self, order: Order) {
        match order {
            Order::Move { steps, feed } => self.push_move(steps, feed),
            Order::Path { mut path, feed } => {
                while let Some(piece) = path.next_piece(&self.kin) {
                    // Pieces were checked to be within reach with the line.
                    if let Ok(piece) = piece {
                        if self.planner.is_full() {
                            self.take();
                        }
                        // Not full: cannot fail.
                        let _ = self.planner.push_piece(&piece, feed);
                    }
                }
            }
            Order::Dwell { ms } => self.wait_ms(ms),
            Order::Pen { ms, .. } => self.wait_ms(ms as u32),
            Order::SetPosition { steps } => {
                self.settle();
                self.planner.set_position(steps);
            }
            Order::Home { .. } | Order::Pause | Order::WaitIdle | Order::Drivers { .. } => {
                self.settle()
            }
            Order::None | Order::ReportPosition => {}
        }
    }

    fn push_move(&mut self, steps: crate::kinematics::Steps, feed: Feed) {
        if self.planner.is_full() {
            self.take();
        }
        // Not full: cannot fail.
        let _ = self.planner.push(steps, feed);
    }

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

    fn wait_ms(&mut self, ms: u32) {
        self.settle();
        self.subticks += ms as u64 * SUBTICKS_PER_S / 1000;
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
}
