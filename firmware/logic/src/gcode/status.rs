//! Grbl 1.1's status report, the answer to `?`:
//! `<Idle|MPos:0.000,0.000,0.000|Bf:15,128|FS:0,0|WCO:0.000,0.000,0.000>`,
//! with `$10` choosing machine or work position and the buffer state,
//! `$13` inches, and the work offset and overrides carried every so
//! often, as Grbl's refresh counters do. The feed and speed overrides
//! (Grbl's real-time bytes 0x90–0x97) are kept here too.

pub use crate::planner::Overrides;
use crate::units::{div_round, Decimal, Milli};
use taut_progmem::text;
use ufmt::{uDisplay, uWrite, uwrite, Formatter};

/// The machine state, in Grbl's words.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum State {
    Idle,
    Run,
    /// A feed hold braking (`Hold:1`) or standing (`Hold:0`).
    Hold {
        standing: bool,
    },
    Jog,
    /// Motion locked until `$X` or homing (the position may be lost).
    Alarm,
    /// The safety door (0x84): stopping (`Door:2`), or stopped with the
    /// door closed, ready to resume (`Door:0`; taut has no door switch).
    Door {
        standing: bool,
    },
    /// `$C`: lines are checked, nothing moves.
    Check,
    Home,
    /// `$SLP`: the drivers off until a reset.
    Sleep,
}

impl uDisplay for State {
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut Formatter<'_, W>) -> Result<(), W::Error> {
        let word = match self {
            State::Idle => text!("Idle"),
            State::Run => text!("Run"),
            State::Hold { standing: true } => text!("Hold:0"),
            State::Hold { standing: false } => text!("Hold:1"),
            State::Jog => text!("Jog"),
            State::Alarm => text!("Alarm"),
            State::Door { standing: true } => text!("Door:0"),
            State::Door { standing: false } => text!("Door:2"),
            State::Check => text!("Check"),
            State::Home => text!("Home"),
            State::Sleep => text!("Sleep"),
        };
        word.fmt(f)
    }
}

/// Grbl's first override byte: 0x90 feed 100 %, 0x91 +10, 0x92 −10,
/// 0x93 +1, 0x94 −1, 0x95 rapid 100 %, 0x96 50 %, 0x97 25 %.
pub const OVERRIDE_BYTES: u8 = 0x90;

/// The override bytes (the planner applies the percentages).
impl Overrides {
    /// Applies the override bytes that came (bit `i`: byte 0x90 + `i`) in
    /// Grbl's order — reset, coarse, fine — the feed kept within 10–200 %;
    /// true if anything changed.
    pub fn apply(&mut self, bits: u8) -> bool {
        let has = |i: u8| bits >> i & 1 != 0;
        let presses = [(1, 10), (2, -10), (3, 1), (4, -1)]
            .iter()
            .filter(|&&(i, _)| has(i))
            .map(|&(_, step)| step)
            .sum();
        self.apply_counted(bits, presses)
    }

    /// As [`Overrides::apply`], the feed's ±10 % and ±1 % presses summed
    /// in `feed` (each one counts, however many came together; bits 1–4
    /// are then ignored): after a reset to 100 % (bit 0) if one came.
    pub fn apply_counted(&mut self, bits: u8, feed: i16) -> bool {
        let before = *self;
        let has = |i: u8| bits >> i & 1 != 0;
        let base = if has(0) { 100 } else { self.feed as i16 };
        self.feed = base.saturating_add(feed).clamp(10, 200) as u8;
        for (i, rapid) in [(5, 100), (6, 50), (7, 25)] {
            if has(i) {
                self.rapid = rapid;
            }
        }
        *self != before
    }
}

/// What a report carries besides the state, the position, the buffer and
/// the feed: the work offset or the overrides, never both.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Extra {
    None,
    Wco,
    Ov,
}

/// Grbl's refresh counters: the work offset every 10th report (30th
/// while busy), the overrides every 10th (20th) and in the report after
/// they change; both soon after a reset.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Refresh {
    wco: u8,
    ov: u8,
}

impl Default for Refresh {
    fn default() -> Self {
        Self::new()
    }
}

impl Refresh {
    pub const fn new() -> Refresh {
        Refresh { wco: 0, ov: 0 }
    }

    /// The overrides changed: in the next report.
    pub fn overrides_changed(&mut self) {
        self.ov = 0;
    }

    /// The work offset changed (Grbl's `system_flag_wco_change`): in the
    /// next report.
    pub fn wco_changed(&mut self) {
        self.wco = 0;
    }

    /// What the next report carries; `busy`: the machine moves or holds.
    pub fn next(&mut self, busy: bool) -> Extra {
        let mut extra = Extra::None;
        match self.wco {
            0 => {
                self.wco = if busy { 29 } else { 9 };
                // Not both in one report: the overrides in the next one.
                self.ov = self.ov.max(1);
                extra = Extra::Wco;
            }
            _ => self.wco -= 1,
        }
        match self.ov {
            0 => {
                self.ov = if busy { 19 } else { 9 };
                Extra::Ov
            }
            _ => {
                self.ov -= 1;
                extra
            }
        }
    }
}

/// A status report. Positions are in the report's places X, Y, Z, in
/// thousandths of mm (or degrees).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Status {
    pub state: State,
    /// The machine position.
    pub position: [Milli; 3],
    /// The work coordinate offset (`WCO`): the work position is the
    /// machine position less it.
    pub wco: [Milli; 3],
    /// Places (bits) whose position is an angle: never in inches.
    pub angles: u8,
    /// Along the path, thousandths of a unit per minute.
    pub feed: Milli,
    /// Free planner blocks and receive bytes.
    pub buffer: (u8, u8),
    /// Places (bits) whose limit switch is closed.
    pub pins: u8,
    pub overrides: Overrides,
    pub extra: Extra,
    /// `$10`: bit 0 machine position (else work position), bit 1 buffer.
    pub fields: u8,
    /// `$13`.
    pub inches: bool,
}

/// Three report places' values as Grbl prints positions and offsets
/// (`$#`, `?`): comma-separated, mm with three decimals or, with `$13`,
/// inches with four; an angle (a bit of `angles`) in degrees.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Places {
    pub values: [Milli; 3],
    pub angles: u8,
    pub inches: bool,
}

impl uDisplay for Places {
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut Formatter<'_, W>) -> Result<(), W::Error> {
        for (p, v) in self.values.iter().enumerate() {
            if p > 0 {
                f.write_char(',')?;
            }
            let inches = self.inches && self.angles >> p & 1 == 0;
            uwrite!(f, "{}", coord_value(*v, inches))?;
        }
        Ok(())
    }
}

/// A length as Grbl prints a coordinate (`printFloat_CoordValue`): mm
/// with three decimals, or inches with four.
pub fn coord_value(v: Milli, inches: bool) -> Decimal {
    match inches {
        true => Decimal(div_round(v.0 as i64 * 100, 254) as i32, 4),
        false => Decimal(v.0, 3),
    }
}

impl Status {
    fn places(&self, values: [Milli; 3]) -> Places {
        Places {
            values,
            angles: self.angles,
            inches: self.inches,
        }
    }
}

impl uDisplay for Status {
    fn fmt<W: uWrite + ?Sized>(&self, f: &mut Formatter<'_, W>) -> Result<(), W::Error> {
        // `$10` bit 0: the machine position, else the work position
        // (report.c line 510).
        let (label, position) = match self.fields & 1 {
            1 => (text!("|MPos:"), self.position),
            _ => (
                text!("|WPos:"),
                core::array::from_fn(|i| Milli(self.position[i].0 - self.wco[i].0)),
            ),
        };
        uwrite!(f, "<{}{}{}", self.state, label, self.places(position))?;
        if self.fields & 2 != 0 {
            uwrite!(f, "{}{},{}", text!("|Bf:"), self.buffer.0, self.buffer.1)?;
        }
        // Whole mm per minute, or inches with one decimal; no spindle.
        let (feed, places) = match self.inches {
            true => (div_round(self.feed.0 as i64, 2540), 1),
            false => (div_round(self.feed.0 as i64, 1000), 0),
        };
        let feed = Decimal(feed as i32, places);
        uwrite!(f, "{}{}{}", text!("|FS:"), feed, text!(",0"))?;
        if self.pins != 0 {
            text!("|Pn:").fmt(f)?;
            for p in 0..3 {
                if self.pins >> p & 1 != 0 {
                    f.write_char((b'X' + p) as char)?;
                }
            }
        }
        match self.extra {
            Extra::None => {}
            Extra::Wco => uwrite!(f, "{}{}", text!("|WCO:"), self.places(self.wco))?,
            Extra::Ov => {
                let o = self.overrides;
                uwrite!(
                    f,
                    "{}{},{}{}",
                    text!("|Ov:"),
                    o.feed,
                    o.rapid,
                    text!(",100")
                )?;
            }
        }
        f.write_char('>')
    }
}

#[cfg(test)]
mod tests;
