//! A plotter's toolpath — where the pen goes, down or up — read the way the
//! machine reads it: G-code through the firmware's own parser, interpreter
//! and kinematics (`taut_logic::gcode`, `interp`, `kinematics`), so a line
//! the machine would refuse (out of travel, out of reach, unknown) is an
//! error here too; or a simulator trace (VCD) through the pulse replay.

use taut_logic::config::MachineConfig;
use taut_logic::coords::CoordData;
use taut_logic::gcode::{Input, Parser};
use taut_logic::interp::{coords, Allowed, Env, Exact, Interpreter, MachineIo, Progress, Wait};
use taut_logic::kinematics::{AnyKinematics, Kinematics, Steps};
use taut_logic::machine::Machine;
use taut_logic::planner::Feed;
use taut_trace::vcd::Signal;

/// A straight piece of the path, mm in the G-code's frame (y up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Move {
    pub from: [f64; 2],
    pub to: [f64; 2],
    pub down: bool,
}

impl Move {
    pub fn len(&self) -> f64 {
        (self.to[0] - self.from[0]).hypot(self.to[1] - self.from[1])
    }
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Toolpath {
    pub moves: Vec<Move>,
}

impl Toolpath {
    /// Length with the pen down, and up, mm.
    pub fn lengths(&self) -> (f64, f64) {
        self.moves
            .iter()
            .fold((0.0, 0.0), |(d, u), m| match m.down {
                true => (d + m.len(), u),
                false => (d, u + m.len()),
            })
    }

    /// Least and greatest x and y of every move.
    pub fn bounds(&self) -> ([f64; 2], [f64; 2]) {
        let mut lo = [f64::MAX; 2];
        let mut hi = [f64::MIN; 2];
        for m in &self.moves {
            for p in [m.from, m.to] {
                lo = [lo[0].min(p[0]), lo[1].min(p[1])];
                hi = [hi[0].max(p[0]), hi[1].max(p[1])];
            }
        }
        (lo, hi)
    }

    fn push(&mut self, from: [f64; 2], to: [f64; 2], down: bool) {
        if from != to {
            self.moves.push(Move { from, to, down });
        }
    }
}

/// The machine as the preview sees it: every move the executor queues
/// (through the forward kinematics) and the pen's angle.
struct Drawing<'a> {
    kin: &'a AnyKinematics,
    cfg: &'a MachineConfig,
    coords: CoordData,
    path: Toolpath,
    at: [f64; 2],
    /// Where the moves queued end, in steps (a seed-003 line counts from it).
    steps: Steps,
    down: bool,
}

impl MachineIo for Drawing<'_> {
    fn coord(&self, index: u8) -> Exact {
        coords::stored(&self.coords, index)
    }
    fn set_coord(&mut self, index: u8, value: &Exact) {
        coords::store(&mut self.coords, index, value)
    }
    fn room(&mut self, _piece: bool) -> Option<Wait> {
        None
    }
    fn steps(&self) -> Steps {
        self.steps
    }
    fn queue(&mut self, steps: &Steps, _feed: Feed) -> bool {
        self.steps = *steps;
        let p = self.kin.forward(steps);
        let to = [f64::from(p[0].0) / 1000.0, f64::from(p[1].0) / 1000.0];
        self.path.push(self.at, to, self.down);
        self.at = to;
        true
    }
    fn idle(&mut self) -> bool {
        true
    }
    fn pen(&mut self, deg: u8) -> bool {
        self.down = deg == self.cfg.pen.down_deg;
        false
    }
    fn drivers(&mut self, _on: bool) {}
    fn idle_delay(&mut self, _ms: u32) {}
    fn pause(&mut self) {}
    fn report_position(&mut self) {}
    fn program_end(&mut self) {}
    fn millis(&self) -> u32 {
        0
    }
}

/// The toolpath of a G-code program on `machine` (its default settings),
/// from the origin with the pen up, read and carried out by the
/// firmware's parser and executor. An error names the line and the
/// firmware's `error:` code and message.
pub fn from_gcode(text: &str, machine: Machine) -> Result<Toolpath, String> {
    let cfg = MachineConfig::defaults(machine);
    let kin = AnyKinematics::of(&cfg).map_err(|e| e.message().to_string())?;
    let env = Env {
        kin: &kin,
        cfg: &cfg,
        allowed: Allowed::ALL,
    };
    let (mut parser, mut interp) = (Parser::new(), Interpreter::new());
    let mut io = Drawing {
        kin: &kin,
        cfg: &cfg,
        coords: CoordData::ZERO,
        path: Toolpath::default(),
        at: [0.0; 2],
        steps: Default::default(),
        down: false,
    };
    let mut line_no = 1;
    let mut bytes: Vec<u8> = text.bytes().collect();
    bytes.push(b'\n');
    for b in bytes {
        let first = parser.first_char();
        let Some(result) = parser.push(b) else {
            continue;
        };
        let here = line_no;
        if b == b'\n' {
            line_no += 1;
        }
        let fail = |code: u8, message: &str| format!("line {here}: error:{code} {message}");
        let (block, jog) = match result {
            Ok(Input::Block(block)) => (block, false),
            Ok(Input::Jog(block)) => (block, true),
            Ok(Input::Realtime(r)) => {
                return Err(format!("line {here}: a real-time byte ({r:?}) in the file"))
            }
            // A program's `%` delimiters, as a card print passes them over.
            Err(_) if first == b'%' => continue,
            // Seed 003's raw-step line.
            Ok(Input::Seed(Some(mv))) => {
                interp
                    .accept_steps(&mv, &env, &mut io)
                    .map_err(|e| fail(e as u8, e.message()))?;
                while interp.run(&env, &mut io) != Progress::Done {}
                continue;
            }
            Ok(Input::Seed(None)) => return Err(format!("line {here}: ? (not a seed-003 line)")),
            Ok(_) => return Err(format!("line {here}: a $ or card command is not a drawing")),
            Err(e) => return Err(fail(e.code(), e.message())),
        };
        interp
            .accept(&block, jog, &env, &mut io)
            .map_err(|e| fail(e as u8, e.message()))?;
        while interp.run(&env, &mut io) != Progress::Done {}
    }
    // The tiny moves joined last, as the firmware queues them when the
    // input ends.
    interp.flush_soon();
    while interp.run(&env, &mut io) != Progress::Done {}
    Ok(io.path)
}

/// The toolpath a plotter's pulses drew (`taut-sim --vcd`): its two drawing
/// motors' steps through the forward kinematics, down while the pen
/// servo's pulses put it at its down angle. Positions count from where the
/// motors stood at power-on.
pub fn from_vcd(signals: &[Signal], machine: Machine) -> Result<Toolpath, String> {
    let cfg = MachineConfig::defaults(machine);
    let points =
        taut_trace::picture::plot_points(signals, &cfg, [0, 0]).map_err(|e| e.to_string())?;
    let mut path = Toolpath::default();
    for w in points.windows(2) {
        path.push([w[0].0 .0, w[0].0 .1], [w[1].0 .0, w[1].0 .1], w[1].1);
    }
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pen_words_moves_and_arcs_as_the_firmware_reads_them() {
        let g = "G21\nG90\nM5\nG0 X10 Y0\nM3\nG1 X20 Y0 F1200\nG3 X10 Y0 R5\nM300 S50\nG0 X0 Y0\n";
        let p = from_gcode(g, Machine::Scara).unwrap();
        // The pieces end on step positions: each corner lies within one
        // motor step of the line or the half circle (centre 15,0; r 5).
        let kin = AnyKinematics::of(&MachineConfig::defaults(Machine::Scara)).unwrap();
        for m in &p.moves {
            for q in [m.from, m.to] {
                let off_line = q[1].abs();
                let off_circle = ((q[0] - 15.0).hypot(q[1]) - 5.0).abs();
                let off = match m.down && q[1] > 0.0 {
                    true => off_line.min(off_circle),
                    false => off_line,
                };
                let step = one_step_mm(&kin, q);
                assert!(off <= step, "{q:?} is {off} mm off, a step is {step} mm");
            }
        }
        // 10 mm straight, a half circle of radius 5 drawn; 10 + 10 mm up:
        // no shorter, and longer only by the zigzag between step positions.
        let (down, up) = p.lengths();
        let half_circle = 10.0 + 5.0 * std::f64::consts::PI;
        assert!(
            down > half_circle - 0.05 && down < half_circle * 1.01,
            "{down}"
        );
        assert!(up > 20.0 - 0.01 && up < 20.0 * 1.01, "{up}");
        // Z lifts and lowers the flatbed's pen.
        let p = from_gcode("G0 Z1\nG0 X5\nG0 Z0\nG1 X6 F100\n", Machine::Flatbed).unwrap();
        assert_eq!(
            p.moves.iter().map(|m| m.down).collect::<Vec<_>>(),
            [false, true]
        );
    }

    #[test]
    fn lines_the_machine_refuses_are_errors_with_its_words() {
        let e = from_gcode("G0 X10\nG0 X150\n", Machine::Flatbed).unwrap_err();
        assert_eq!(e, "line 2: error:15 Travel exceeded (soft limit)");
        let e = from_gcode("G1 X10\n", Machine::Drum).unwrap_err();
        assert!(e.starts_with("line 1: error:22"), "{e}");
        // A move with the pen's Z: the pen first, then the move.
        let p = from_gcode("G0 Z1\nG1 X1 Z-1 F100\n", Machine::Flatbed).unwrap();
        assert_eq!(p.moves.iter().map(|m| m.down).collect::<Vec<_>>(), [true]);
        let e = from_gcode("G0 X900 Y0\n", Machine::Scara).unwrap_err();
        assert!(e.starts_with("line 1: error:"), "{e}");
    }

    /// How far the pen goes, mm, for one step of either drawing motor at `q`.
    fn one_step_mm(kin: &AnyKinematics, q: [f64; 2]) -> f64 {
        use taut_logic::units::Milli;
        let at = |x: f64| Milli((x * 1000.0).round() as i32);
        let steps = kin.inverse(&[at(q[0]), at(q[1]), Milli(0)]).unwrap();
        let here = kin.forward(&steps);
        let mut most: f64 = 0.0;
        for axis in 0..2 {
            for d in [-1, 1] {
                let mut s = steps;
                s[axis] += d;
                let p = kin.forward(&s);
                let dx = f64::from(p[0].0 - here[0].0) / 1000.0;
                let dy = f64::from(p[1].0 - here[1].0) / 1000.0;
                most = most.max(dx.hypot(dy));
            }
        }
        most
    }
}
