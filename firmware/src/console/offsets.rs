//! `$#`: the work coordinate data, `G92` and the tool length offset, as
//! Grbl's `report_ngc_parameters` prints them.

use super::Console;
use crate::{flash_str, reply};
use taut_logic::config::MachineConfig;
use taut_logic::coords::{CoordData, Slot};
use taut_logic::gcode::{coord_value, Places};
use taut_logic::kinematics::Position;
use taut_logic::settings::grbl::{report_angles, report_axes};
use taut_logic::units::Milli;
use ufmt::uwrite;

/// What the status report takes from the console: where the work
/// coordinates are.
pub struct Frame {
    /// The work coordinate offset of each channel (`WCO`).
    pub wco: Position,
    /// The programmed position: a plotter's pen channel reports it (no
    /// motor counts its `Z`).
    pub programmed: Position,
    /// The offset changed since the last report (Grbl's WCO refresh).
    pub changed: bool,
}

impl Console {
    /// The work coordinates for the status report.
    pub fn frame(&mut self) -> Frame {
        Frame {
            wco: self.interp.wco(),
            programmed: self.interp.target(),
            changed: self.interp.take_wco_changed(),
        }
    }

    /// Line `line` of `$#` (`report_ngc_parameters`): `G54`…`G59`, `G28`,
    /// `G30` from the coordinate data, `G92` and `TLO` from the executor,
    /// `PRB` (taut has no probe: zero, not taken); `false` past the last.
    #[inline(never)]
    #[optimize(size)]
    pub(super) fn offsets_line(&self, line: u8, cfg: &MachineConfig, data: &CoordData) -> bool {
        let (g92, tlo) = self.interp.offsets();
        let places = |p: Position| Places {
            values: report_axes(cfg.machine).map(|a| p[a.index()]),
            angles: report_angles(cfg.machine),
            inches: cfg.report_inches,
        };
        let mut r = reply::line();
        let _ = match line {
            0..=5 => uwrite!(r, "{}{}:", flash_str!("[G"), 54 + line),
            6 | 7 => uwrite!(
                r,
                "{}{}:",
                flash_str!("[G"),
                if line == 6 { 28 } else { 30 }
            ),
            8 => uwrite!(r, "{}", flash_str!("[G92:")),
            9 => uwrite!(r, "{}", flash_str!("[TLO:")),
            10 => uwrite!(r, "{}", flash_str!("[PRB:")),
            _ => return false,
        };
        let _ = match line {
            0..=7 => {
                let values = Slot::at(line as usize).map_or([Milli::ZERO; 3], |s| data.get(s));
                uwrite!(r, "{}]", places(values))
            }
            8 => uwrite!(r, "{}]", places(g92)),
            9 => uwrite!(r, "{}]", coord_value(tlo, cfg.report_inches)),
            _ => uwrite!(r, "{}{}", places([Milli::ZERO; 3]), flash_str!(":0]")),
        };
        r.send();
        true
    }
}
