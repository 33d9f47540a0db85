//! The five machines one image drives, chosen at run time (`$machine=`):
//! their names, what each calls its channels and its G-code words. Their
//! defaults (the seeds' figures) are `MachineConfig::defaults`, their
//! kinematics `AnyKinematics::of`.

use crate::axis::{Axis, AXES};
use taut_progmem::{text, Text};

/// The string-art machine's words: base `C`, radial `X`, drill `Z`.
pub const CYLINDRICAL: [u8; AXES] = *b"CXZ";
/// A plotter's or an arm's words.
pub const CARTESIAN: [u8; AXES] = *b"XYZ";

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Machine {
    /// The rotating board, radial carriage and drill.
    #[default]
    StringArt = 0,
    /// Seed 001: X along the drum, Y the drum's turn (mm of paper).
    Drum = 1,
    /// Seed 002: X 140 mm, homed at start-up; Y the paper feed.
    Flatbed = 2,
    /// Seed 003: two motors hang the pen on strings or chains.
    Whiteboard = 3,
    /// Seed 004: shoulder and elbow, Klipper's kinematics.
    Scara = 4,
}

impl Machine {
    pub const ALL: [Machine; 5] = [
        Machine::StringArt,
        Machine::Drum,
        Machine::Flatbed,
        Machine::Whiteboard,
        Machine::Scara,
    ];

    /// The name `$machine=` takes and `$$` prints.
    pub fn name(self) -> Text {
        taut_progmem::text_table!(Machine; [
            StringArt => "string_art",
            Drum => "drum",
            Flatbed => "flatbed",
            Whiteboard => "whiteboard",
            Scara => "scara",
        ])
        .get(self as usize)
    }

    /// The machine named `name`, in any case.
    pub fn parse(name: &[u8]) -> Option<Machine> {
        Machine::ALL
            .into_iter()
            .find(|m| m.name().eq_ignore_ascii_case(name))
    }

    pub fn from_index(i: u8) -> Option<Machine> {
        Machine::ALL.get(i as usize).copied()
    }

    /// What the machine calls each channel: setting names
    /// (`<channel>_max_rate`), log lines and the VCD's signals.
    pub fn channel(self, axis: Axis) -> Text {
        // A table in flash by machine, then axis: a `match` on the pair
        // cost 176 B of code. Texts named once, not a copy per row.
        const Z: Text = text!("z");
        const X: Text = text!("x");
        const Y: Text = text!("y");
        const N: usize = Machine::ALL.len() * AXES;
        const _: () = {
            let mut m = 0;
            while m < Machine::ALL.len() {
                assert!(Machine::ALL[m] as usize == m);
                m += 1;
            }
            assert!(Axis::Base as usize == 0 && Axis::Radial as usize == 1);
            assert!(Axis::Drill as usize == 2 && AXES == 3);
        };
        let names = taut_progmem::table!(Text; N; [
            text!("base"), text!("radial"), text!("drill"), // StringArt
            X, Y, Z, // Drum
            X, Y, Z, // Flatbed
            text!("left"), text!("right"), Z, // Whiteboard
            text!("shoulder"), text!("elbow"), Z, // Scara
        ]);
        names.get(self as usize * AXES + axis as usize)
    }

    /// The G-code word of each coordinate.
    pub const fn words(self) -> [u8; AXES] {
        match self {
            Machine::StringArt => CYLINDRICAL,
            _ => CARTESIAN,
        }
    }

    /// Whether the string-art job (drill and wind from the card) runs.
    pub const fn is_string_art(self) -> bool {
        matches!(self, Machine::StringArt)
    }
}

#[cfg(test)]
mod tests;
