//! `$G`: the parser state as Grbl 1.1's `report_gcode_modes` prints it.

use super::{Interpreter, FLOOD, MIST};
use crate::gcode::{Distance, FeedMode, MotionMode, Plane, Spindle, Units};
use crate::units::{div_round, Decimal, Milli};
use taut_progmem::text;
use ufmt::{uDisplay, uWrite, uwrite, Formatter};

/// The modal state as `$G` reports it: `[GC:` this `]`, e.g. `G0 G54 G17
/// G21 G90 G94 M5 M9 T0 F0 S0`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ParserState {
    motion: u8,
    coord: u8,
    plane: u8,
    units: u8,
    distance: u8,
    feed_mode: u8,
    spindle: u8,
    coolant: u8,
    tool: u8,
    /// mm per minute (or inverse minutes in `G93`).
    feed: Milli,
    speed: Milli,
    /// `$13`: the feed in inches per minute.
    inches: bool,
}

impl Interpreter {
    /// Grbl's `$G` of the modal state; `inches` as `$13` says.
    pub fn parser_state(&self, inches: bool) -> ParserState {
        let m = &self.modal;
        ParserState {
            motion: match m.motion {
                MotionMode::Seek => 0,
                MotionMode::Linear => 1,
                MotionMode::CwArc => 2,
                MotionMode::CcwArc => 3,
                MotionMode::None => 80,
            },
            coord: 54 + m.coord,
            plane: match m.plane {
                Plane::Xy => 17,
                Plane::Zx => 18,
                Plane::Yz => 19,
            },
            units: match m.units {
                Units::Inch => 20,
                Units::Mm => 21,
            },
            distance: match m.distance {
                Distance::Absolute => 90,
                Distance::Relative => 91,
            },
            feed_mode: match m.feed_mode {
                FeedMode::InverseTime => 93,
                FeedMode::PerMinute => 94,
            },
            spindle: match m.spindle {
                Spindle::Cw => 3,
                Spindle::Ccw => 4,
                Spindle::Off => 5,
            },
            coolant: m.coolant,
            tool: self.tool,
            feed: self.feed,
            speed: self.speed,
            inches,
        }
    }
}

impl uDisplay for ParserState {
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut Formatter<'_, W>) -> Result<(), W::Error> {
        // The fixed words as flash text: literals would sit in the AVR's SRAM.
        let g = text!(" G");
        uwrite!(
            f,
            "G{}{}{}{}{}{}{}{}{}{}{}{}{}",
            self.motion,
            g,
            self.coord,
            g,
            self.plane,
            g,
            self.units,
            g,
            self.distance,
            g,
            self.feed_mode,
            text!(" M"),
            self.spindle
        )?;
        match self.coolant {
            0 => text!(" M9").fmt(f)?,
            c => {
                if c & MIST != 0 {
                    text!(" M7").fmt(f)?;
                }
                if c & FLOOD != 0 {
                    text!(" M8").fmt(f)?;
                }
            }
        }
        // Grbl's rate: whole mm per minute, or inches with one decimal.
        let feed = match self.inches {
            true => Decimal(div_round(self.feed.0 as i64, 2540) as i32, 1),
            false => Decimal(div_round(self.feed.0 as i64, 1000) as i32, 0),
        };
        let speed = Decimal(div_round(self.speed.0 as i64, 1000) as i32, 0);
        uwrite!(
            f,
            "{}{}{}{}{}{}",
            text!(" T"),
            self.tool,
            text!(" F"),
            feed,
            text!(" S"),
            speed
        )
    }
}
