//! Work coordinate data, as Grbl keeps it in EEPROM: the offsets of the
//! six work coordinate systems `G54`–`G59` and the positions `G28.1` and
//! `G30.1` store. `G92`'s offset is not kept (Grbl's neither): it lasts
//! until a reset. Values are machine coordinates in thousandths of each
//! position word's unit (µm; millidegrees for the string-art base), one
//! per place of the interpreter's position (the kinematics' `words()`:
//! X Y Z on the plotters, the string-art machine's channels).
//!
//! How the G-code executor uses it (the firmware's `Store` owns the copy
//! in force and keeps it in EEPROM, two copies, cut-safe):
//! - at boot: `Store::load` has read it; take the active system's offset
//!   with [`CoordData::get`] (`store.coords()`);
//! - `G10 L2`/`L20 Pn`, `G28.1`, `G30.1`: `store.set_coords(slot, values)`
//!   ([`CoordData::set`] on the store's copy, then written in the
//!   background; reads see the new values at once);
//! - `G28`/`G30`: the stored position with [`CoordData::get`];
//! - `$#`: every slot in [`Slot::at`] order;
//! - `$RST=#` (and `$RST=*`): [`CoordData::ZERO`].

use crate::axis::AXES;
use crate::units::Milli;

/// What Grbl stores: `$#` lists them in this order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    G54,
    G55,
    G56,
    G57,
    G58,
    G59,
    /// `G28.1`'s position, where `G28` goes.
    G28,
    /// `G30.1`'s position, where `G30` goes.
    G30,
}

/// Slots kept: six work systems and two positions.
pub const SLOTS: usize = 8;

impl Slot {
    /// The slot at `index` (`$#` order), worked out: a table would sit in
    /// SRAM on the AVR.
    pub const fn at(index: usize) -> Option<Slot> {
        Some(match index {
            0 => Slot::G54,
            1 => Slot::G55,
            2 => Slot::G56,
            3 => Slot::G57,
            4 => Slot::G58,
            5 => Slot::G59,
            6 => Slot::G28,
            7 => Slot::G30,
            _ => return None,
        })
    }

    /// The work system of `G10`'s `P1`…`P6` (`P0`, the active one, is the
    /// executor's to resolve).
    pub const fn work(p: u8) -> Option<Slot> {
        match p {
            1..=6 => Slot::at(p as usize - 1),
            _ => None,
        }
    }

    pub const fn index(self) -> usize {
        self as usize
    }
}

/// Every slot's values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CoordData {
    values: [[Milli; AXES]; SLOTS],
}

impl Default for CoordData {
    fn default() -> Self {
        CoordData::ZERO
    }
}

/// Bytes of the data in EEPROM: 4 a value.
pub const PAYLOAD: u16 = (SLOTS * AXES * 4) as u16;

impl CoordData {
    /// What a new board and `$RST=#` hold.
    pub const ZERO: CoordData = CoordData {
        values: [[Milli(0); AXES]; SLOTS],
    };

    pub fn get(&self, slot: Slot) -> [Milli; AXES] {
        self.values[slot.index()]
    }

    pub fn set(&mut self, slot: Slot, values: [Milli; AXES]) {
        self.values[slot.index()] = values;
    }

    /// Part `k` of the EEPROM payload: one value, little-endian (the
    /// store's writer inverts it). `None` past the last.
    pub fn part(&self, k: u8) -> Option<[u8; 4]> {
        let k = k as usize;
        let slot = self.values.get(k / AXES)?;
        Some(slot[k % AXES].0.to_le_bytes())
    }

    /// The data from a payload read through `byte(i)` (already
    /// un-inverted). Every value is taken: a position needs no check.
    pub fn decode(byte: impl Fn(u16) -> u8) -> CoordData {
        let mut data = CoordData::ZERO;
        data.decode_into(byte);
        data
    }

    /// [`CoordData::decode`] in place (no copy on the AVR's stack).
    pub fn decode_into(&mut self, byte: impl Fn(u16) -> u8) {
        for (s, slot) in self.values.iter_mut().enumerate() {
            for (a, v) in slot.iter_mut().enumerate() {
                let at = ((s * AXES + a) * 4) as u16;
                *v = Milli(i32::from_le_bytes([
                    byte(at),
                    byte(at + 1),
                    byte(at + 2),
                    byte(at + 3),
                ]));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slots_are_numbered_as_dollar_hash_lists_them() {
        for i in 0..SLOTS {
            assert_eq!(Slot::at(i).unwrap().index(), i);
        }
        assert_eq!(Slot::at(SLOTS), None);
        assert_eq!(Slot::work(1), Some(Slot::G54));
        assert_eq!(Slot::work(6), Some(Slot::G59));
        assert_eq!(Slot::work(0), None);
        assert_eq!(Slot::work(7), None);
    }

    #[test]
    fn the_payload_reads_back() {
        let mut d = CoordData::ZERO;
        d.set(Slot::G55, [Milli(-1), Milli(2_000), Milli(i32::MAX)]);
        d.set(Slot::G30, [Milli(i32::MIN), Milli(7), Milli(-300_500)]);
        let bytes: std::vec::Vec<u8> = (0..).map_while(|k| d.part(k)).flatten().collect();
        assert_eq!(bytes.len(), PAYLOAD as usize);
        assert_eq!(CoordData::decode(|i| bytes[i as usize]), d);
        assert_eq!(d.get(Slot::G54), [Milli(0); AXES]);
    }
}
