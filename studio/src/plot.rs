//! Plotter output shared by `vectorize` and `text`: strokes (polylines in
//! mm, the G-code's frame, y up) to the G-code the firmware reads, with the
//! pen commands of the machine's profile, then read back through the
//! firmware's own interpreter (`toolpath`): a drawing that leaves the
//! machine's travel or reach is refused here, with the firmware's words.

use crate::toolpath::{self, Toolpath};
use crate::vectorize::trace::Polyline;
use taut_logic::machine::Machine;

/// The plotters and the arm (`$machine=` names).
pub fn machine(name: &str) -> Result<Machine, String> {
    match Machine::parse(name.as_bytes()) {
        Some(Machine::StringArt) | None => Err(format!(
            "--machine {name}: flatbed, drum, whiteboard or scara"
        )),
        Some(m) => Ok(m),
    }
}

/// Pen down and pen up in each machine's dialect: the flatbed's seed (002)
/// lifts with `Z`, the whiteboard speaks the Inkscape unicorn extension's
/// `M300`, the drum and the arm Grbl's servo fork `M3`/`M5`.
pub fn pen_words(machine: Machine) -> (&'static str, &'static str) {
    match machine {
        Machine::Flatbed => ("G0 Z0", "G0 Z1"),
        Machine::Whiteboard => ("M300 S30", "M300 S50"),
        _ => ("M3", "M5"),
    }
}

/// Where a drawing's lower left corner goes by default: the origin, but
/// the whiteboard centres it on its origin (its reach is all round).
pub fn default_corner(machine: Machine, size: [f64; 2]) -> [f64; 2] {
    match machine {
        Machine::Whiteboard => [-size[0] / 2.0, -size[1] / 2.0],
        _ => [0.0, 0.0],
    }
}

/// A G-code number: mm to the micrometre.
fn n(v: f64) -> String {
    crate::svg::num(v)
}

/// A pass of the drawing with one pen: its name and strokes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Layer {
    pub name: String,
    pub strokes: Vec<Polyline>,
}

/// Text safe in a G-code comment: printable ASCII without the real-time
/// bytes (`?`, `!`, `~` act even inside a comment), parentheses or `;`,
/// at most `max` characters.
fn comment_text(text: &str, max: usize) -> String {
    text.chars()
        .filter(|c| !"?!~();%\r\n".contains(*c))
        .map(|c| match c.is_ascii_graphic() || c == ' ' {
            true => c,
            false => '_',
        })
        .take(max)
        .collect()
}

/// The program: units, mode and drivers on, each stroke drawn pen down at
/// `feed` mm/min after a pen-up rapid to its start, then pen up and home.
pub fn gcode(strokes: &[Polyline], machine: Machine, feed: f64, title: &str) -> String {
    let one = [Layer {
        name: String::new(),
        strokes: strokes.to_vec(),
    }];
    gcode_layers(&one, machine, feed, title)
}

/// The program of several passes: before each pass after the first, the
/// pen is lifted and the machine stops (`M0`, a program pause: Grbl holds
/// until cycle start, `~`) on a line whose comment names the pass,
/// `(MSG, …)` — the LinuxCNC/grblHAL form that such firmware reports as
/// `[MSG:…]`, and the line CNCjs shows in its pause notice and
/// `taut send` prints while the machine waits.
pub fn gcode_layers(layers: &[Layer], machine: Machine, feed: f64, title: &str) -> String {
    let (down, up) = pen_words(machine);
    let title = comment_text(title, 100);
    // The drivers start off at power-on: M17 switches them on.
    let mut g = format!("; {title}\nG21\nG90\nM17\n{up}\n");
    let mut feed_set = false;
    let drawn: Vec<&Layer> = layers
        .iter()
        .filter(|l| l.strokes.iter().any(|s| s.len() >= 2))
        .collect();
    for (k, layer) in drawn.iter().enumerate() {
        if drawn.len() > 1 {
            let name = comment_text(&layer.name, 40);
            g += &format!("; pass {} of {}: {name}\n", k + 1, drawn.len());
            if k > 0 {
                g += &format!(
                    "M0 (MSG, change the pen: pass {} of {}, {name})\n",
                    k + 1,
                    drawn.len()
                );
            }
        }
        for s in layer.strokes.iter().filter(|s| s.len() >= 2) {
            g += &format!("G0 X{} Y{}\n{down}\n", n(s[0][0]), n(s[0][1]));
            for p in &s[1..] {
                g += &format!("G1 X{} Y{}", n(p[0]), n(p[1]));
                if !feed_set {
                    g += &format!(" F{}", n(feed));
                    feed_set = true;
                }
                g.push('\n');
            }
            g += up;
            g.push('\n');
        }
    }
    g += "G0 X0 Y0\n";
    g
}

/// The G-code of `strokes` and its toolpath as the firmware reads it.
pub fn plot(
    strokes: &[Polyline],
    machine: Machine,
    feed: f64,
    title: &str,
) -> Result<(String, Toolpath), String> {
    let one = [Layer {
        name: String::new(),
        strokes: strokes.to_vec(),
    }];
    plot_layers(&one, machine, feed, title)
}

/// The G-code of the passes and its toolpath as the firmware reads it.
pub fn plot_layers(
    layers: &[Layer],
    machine: Machine,
    feed: f64,
    title: &str,
) -> Result<(String, Toolpath), String> {
    if feed.is_nan() || feed < 10.0 {
        return Err("--feed must be at least 10 mm/min".into());
    }
    let g = gcode_layers(layers, machine, feed, title);
    let path = toolpath::from_gcode(&g, machine).map_err(|e| {
        let name = machine.name().to_string();
        format!("the drawing does not fit the {name} (G-code {e}): make it smaller or move it with --at")
    })?;
    Ok((g, path))
}

/// The machine time of a program by the firmware's own planner, with the
/// machine's default settings, seconds (pauses for a pen change not
/// counted).
pub fn seconds(gcode: &str, machine: Machine) -> f64 {
    let cfg = taut_logic::config::MachineConfig::defaults(machine);
    match taut_logic::interp::estimate::GcodeTime::new(&cfg) {
        Some(mut t) => {
            t.push(gcode.as_bytes());
            t.push(b"\n");
            t.finish()
        }
        None => 0.0,
    }
}

/// Half the pen's largest move for one step of either motor at `p`, mm:
/// how closely the machine can follow a curve there.
pub fn half_step_mm(machine: Machine, p: [f64; 2]) -> f64 {
    use taut_logic::kinematics::{AnyKinematics, Kinematics};
    use taut_logic::units::Milli;
    let cfg = taut_logic::config::MachineConfig::defaults(machine);
    let Ok(kin) = AnyKinematics::of(&cfg) else {
        return 0.01;
    };
    let um = |v: f64| Milli((v * 1000.0).round() as i32);
    let mut pos = [Milli(0); taut_logic::axis::AXES];
    pos[0] = um(p[0]);
    pos[1] = um(p[1]);
    let Ok(steps) = kin.inverse(&pos) else {
        return 0.01;
    };
    let at = |s: &taut_logic::kinematics::Steps| {
        let q = kin.forward(s);
        [f64::from(q[0].0) / 1000.0, f64::from(q[1].0) / 1000.0]
    };
    let here = at(&steps);
    let mut most: f64 = 0.0;
    for axis in 0..2 {
        let mut s = steps;
        s[axis] += 1;
        let q = at(&s);
        most = most.max((q[0] - here[0]).hypot(q[1] - here[1]));
    }
    (most / 2.0).max(0.0005)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_machine_gets_its_pen_words_and_the_path_reads_back() {
        let strokes = vec![
            vec![[1.0, 1.0], [5.0, 1.0], [5.0, 4.0]],
            vec![[8.0, 8.0], [9.0, 9.5]],
        ];
        for m in [
            Machine::Drum,
            Machine::Flatbed,
            Machine::Whiteboard,
            Machine::Scara,
        ] {
            let (g, path) = plot(&strokes, m, 1200.0, "test? drawing").unwrap();
            let (down, up) = pen_words(m);
            assert_eq!(g.matches(&format!("{down}\n")).count(), 2, "{m:?}");
            assert_eq!(g.matches(&format!("{up}\n")).count(), 3, "{m:?}");
            assert!(g.starts_with("; test drawing\n") && g.contains("G1 X5 Y1 F1200\n"));
            let (drawn, _) = path.lengths();
            // To a step of the coarsest motor (the drum's 0.14 mm).
            assert!(
                (drawn - 7.0 - 1.0f64.hypot(1.5)).abs() < 0.15,
                "{m:?}: {drawn}"
            );
        }
        assert_eq!(
            machine("string_art").unwrap_err(),
            "--machine string_art: flatbed, drum, whiteboard or scara"
        );
    }

    #[test]
    fn a_drawing_past_the_flatbeds_travel_is_refused() {
        let wide = vec![vec![[0.0, 0.0], [150.0, 0.0]]];
        let e = plot(&wide, Machine::Flatbed, 1200.0, "").unwrap_err();
        assert!(
            e.starts_with("the drawing does not fit the flatbed (G-code line 8: error:15"),
            "{e}"
        );
        assert!(plot(&wide, Machine::Drum, 1200.0, "").is_ok());
    }
}
