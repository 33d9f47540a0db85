//! Seed 001's test patterns, for any plotter (`$T1`, `$T5`, `$T6`, `$T7`):
//! G-code the console reads as if it came over the line, each from where
//! the pen stands (relative moves; the pen up between strokes), kept in
//! flash. `$T7`'s lines through all eight octants catch a sign or octant
//! slip at a glance; `$T6`'s target, the arcs; `$T5`'s "ABC", the text.

use taut_progmem::{text, Text};

/// The pattern of `$T<n>`.
pub fn pattern(n: u8) -> Option<Text> {
    Some(match n {
        // The pen up over 0,0.
        1 => text!("M5\nG90 G0 X0 Y0\n"),
        // "ABC", 10 mm high.
        5 => text!(
            "M5\nG91\nM3\nG1 X4 Y10 F1200\nG1 X4 Y-10\nM5\nG0 X-6.4 Y4\nM3\nG1 X4.8 Y0\nM5\n\
             G0 X3.6 Y-4\nM3\nG1 X0 Y10\nG1 X3 Y0\nG2 X0 Y-5 I0 J-2.5\nG1 X-3 Y0\nM5\n\
             G0 X3 Y0\nM3\nG2 X0 Y-5 I0 J-2.5\nG1 X-3 Y0\nM5\n\
             G0 X16.536 Y8.536\nM3\nG3 X0 Y-7.072 I-3.536 J-3.536\nM5\nG90\n"
        ),
        // A target: two circles and a cross, round where the pen stands.
        6 => text!(
            "M5\nG91\nG0 X10\nM3\nG3 X0 Y0 I-10 J0\nM5\nG0 X10\nM3\nG3 X0 Y0 I-20 J0\nM5\n\
             G0 X5\nM3\nG1 X-50\nM5\nG0 X25 Y-25\nM3\nG1 Y50\nM5\nG0 Y-25\nG90\n"
        ),
        // Lines out from where the pen stands through all eight octants.
        7 => text!(
            "M5\nG91\nM3\nG1 X20 Y8 F1200\nG1 X-20 Y-8\nG1 X8 Y20\nG1 X-8 Y-20\n\
             G1 X-8 Y20\nG1 X8 Y-20\nG1 X-20 Y8\nG1 X20 Y-8\nG1 X-20 Y-8\nG1 X20 Y8\n\
             G1 X-8 Y-20\nG1 X8 Y20\nG1 X8 Y-20\nG1 X-8 Y20\nG1 X20 Y-8\nG1 X-20 Y8\nM5\nG90\n"
        ),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gcode::{Input, Parser};

    /// Every pattern parses, line by line.
    #[test]
    fn every_pattern_parses_and_returns_to_its_start() {
        for n in [1, 5, 6, 7] {
            let t = pattern(n).unwrap();
            let mut parser = Parser::new();
            let mut lines = 0;
            for b in t.bytes() {
                match parser.push(b) {
                    Some(Ok(Input::Block(_))) => lines += 1,
                    Some(other) => panic!("$T{n}: {other:?}"),
                    None => {}
                }
            }
            assert!(lines >= 2, "$T{n}");
        }
        assert!(pattern(2).is_none());
    }
}
