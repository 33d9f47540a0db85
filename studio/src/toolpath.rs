//! A plotter's toolpath — where the pen goes, down or up — read the way the
//! machine reads it: G-code through the firmware's own parser, interpreter
//! and kinematics (`taut_logic::gcode`, `interp`, `kinematics`), so a line
//! the machine would refuse (out of travel, out of reach, unknown) is an
//! error here too; or a simulator trace (VCD) through the pulse replay.

use taut_logic::config::MachineConfig;
use taut_logic::gcode::{Input, Parser};
use taut_logic::interp::{Allowed, Interpreter, Order};
use taut_logic::kinematics::{AnyKinematics, Kinematics, Position};
use taut_logic::machine::Machine;
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

fn mm(p: &Position) -> [f64; 2] {
    [f64::from(p[0].0) / 1000.0, f64::from(p[1].0) / 1000.0]
}

/// The toolpath of a G-code program on `machine` (its default settings),
/// from the origin with the pen up. An error names the line and the
/// firmware's `error:` code and message.
pub fn from_gcode(text: &str, machine: Machine) -> Result<Toolpath, String> {
    let cfg = MachineConfig::defaults(machine);
    let kin = AnyKinematics::of(&cfg).map_err(|e| e.message().to_string())?;
    let allowed = Allowed {
        motion: true,
        position_known: true,
    };
    let (mut parser, mut interp) = (Parser::new(), Interpreter::new());
    let mut path = Toolpath::default();
    let (mut at, mut down, mut line_no) = ([0.0; 2], false, 1);
    let mut bytes: Vec<u8> = text.bytes().collect();
    bytes.push(b'\n');
    for b in bytes {
        let Some(result) = parser.push(b) else {
            continue;
        };
        let here = line_no;
        if b == b'\n' {
            line_no += 1;
        }
        let fail = |code: u8, message: &str| format!("line {here}: error:{code} {message}");
        let line = match result {
            Ok(Input::Line(line)) => line,
            Ok(Input::Realtime(r)) => {
                return Err(format!("line {here}: a real-time byte ({r:?}) in the file"))
            }
            Ok(_) => return Err(format!("line {here}: a $ or card command is not a drawing")),
            Err(e) => return Err(fail(e.code(), e.message())),
        };
        let planned = interp
            .plan(&line, &kin, &cfg, allowed)
            .map_err(|e| fail(e as u8, e.message()))?;
        match planned.order {
            Order::Move { steps, .. } | Order::SetPosition { steps } => {
                let to = mm(&kin.forward(&steps));
                if matches!(planned.order, Order::Move { .. }) {
                    path.push(at, to, down);
                }
                at = to;
            }
            Order::Path { path: pieces, .. } => {
                for p in pieces {
                    let to = mm(&p);
                    path.push(at, to, down);
                    at = to;
                }
            }
            Order::Pen { deg, .. } => down = deg == cfg.pen.down_deg,
            Order::Home { .. } => return Err(fail(0, "homing (G28) cannot be previewed")),
            _ => {}
        }
        interp.commit(&planned);
    }
    Ok(path)
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
        let (down, up) = p.lengths();
        // 10 mm straight, a half circle of radius 5 drawn; 10 + 10 mm up.
        assert!(
            (down - 10.0 - 5.0 * std::f64::consts::PI).abs() < 0.05,
            "{down}"
        );
        assert!((up - 20.0).abs() < 0.01, "{up}");
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
        let e = from_gcode("G0 X1 Z1\n", Machine::Flatbed).unwrap_err();
        assert!(e.starts_with("line 1: error:73"), "{e}");
        let e = from_gcode("G0 X900 Y0\n", Machine::Scara).unwrap_err();
        assert!(e.starts_with("line 1: error:"), "{e}");
    }
}
