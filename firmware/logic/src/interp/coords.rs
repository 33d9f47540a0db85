//! Work coordinates: positions kept exactly, and the coordinate data Grbl
//! keeps in EEPROM (`settings_read_coord_data`): the six work systems
//! `G54`–`G59`, then the `G28` and `G30` positions.

use crate::axis::AXES;
use crate::kinematics::Position;
use crate::units::{div_round, Milli};

/// A position or offset per channel in millionths of its unit
/// (nanometres, or micro-degrees of the base): the programmed position
/// is kept in these, exactly as the words added up, and rounded to
/// steps once, from the absolute target.
pub type Exact = [i64; AXES];

/// Millionths per thousandth.
const PER_MILLI: i64 = 1000;

/// Grbl's coordinate data indices: `G54`…`G59` are 0…5.
pub const G28: u8 = 6;
pub const G30: u8 = 7;
/// How many sets Grbl keeps.
pub const COORD_SETS: usize = 8;

/// `exact` in thousandths (µm), each rounded once.
pub fn milli(exact: &Exact) -> Position {
    exact.map(|v| Milli(div_round(v, PER_MILLI).clamp(-(i32::MAX as i64), i32::MAX as i64) as i32))
}

/// `pos` (thousandths) as millionths.
pub fn exact(pos: &Position) -> Exact {
    pos.map(|m| m.0 as i64 * PER_MILLI)
}

/// The coordinate data in RAM, to the µm (as the EEPROM keeps them):
/// 96 bytes. Until it has its place in EEPROM, a reset keeps it and a
/// power cut loses it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CoordTable {
    sets: [[i32; AXES]; COORD_SETS],
}

impl Default for CoordTable {
    fn default() -> Self {
        Self::new()
    }
}

impl CoordTable {
    pub const fn new() -> CoordTable {
        CoordTable {
            sets: [[0; AXES]; COORD_SETS],
        }
    }

    pub fn get(&self, index: u8) -> Exact {
        let set = self.sets.get(index as usize).copied().unwrap_or([0; AXES]);
        set.map(|v| v as i64 * PER_MILLI)
    }

    pub fn set(&mut self, index: u8, value: &Exact) {
        if let Some(set) = self.sets.get_mut(index as usize) {
            *set = milli(value).map(|m| m.0);
        }
    }

    /// `$RST=#`: every set zero.
    pub fn clear(&mut self) {
        *self = CoordTable::new();
    }
}
