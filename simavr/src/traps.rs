//! The few instructions a batched run cannot see go by, found in the code
//! before it runs: every `cli` (interrupts masked without any register
//! write simavr could report) is replaced in the simulated flash by an
//! invalid opcode, which simavr reports, so the harness can mask the
//! interrupts itself and end the batch right after; the reset vector gets
//! one too, so a jump to address 0 stops the run where it lands.
//!
//! Only words inside functions (the ELF's function symbols, or the whole
//! program of a hand-assembled one) are decoded, so constants kept in flash
//! and read with `lpm` are never touched.

/// An invalid opcode (simavr raises its bad-opcode IRQ and runs on).
pub(crate) const TRAP: u16 = 0x0001;
/// `cli` (`bclr 7`).
pub(crate) const CLI: u16 = 0x94F8;

/// Words taken by the instruction starting with `op`: 2 for `jmp`, `call`,
/// `lds` and `sts`, 1 otherwise.
pub(crate) fn words(op: u16) -> u32 {
    let long = op & 0xFE0C == 0x940C || op & 0xFC0F == 0x9000;
    1 + u32::from(long)
}

/// Byte addresses of the `cli` instructions in `code` (words from byte
/// address `start`, decoded one instruction after another).
pub(crate) fn cli_sites(code: &[u16], start: u32) -> Vec<u32> {
    let mut sites = Vec::new();
    let mut i = 0;
    while i < code.len() {
        if code[i] == CLI {
            sites.push(start + 2 * i as u32);
        }
        i += words(code[i]) as usize;
    }
    sites
}

/// Where execution came from when it reached address 0 (the instruction
/// that jumped there ended at the cycle it arrived), for a run that did not
/// see it go: the last instruction that moved the stack pointer if it was a
/// call or return ending exactly then (a `ret` popping 0, an `icall`
/// through a null pointer), else the first direct jump to 0 or indirect jump
/// with Z = 0 in the code.
pub(crate) struct ZeroOrigin<'a> {
    /// Flash words from address 0.
    pub flash: &'a [u16],
    /// The code's function ranges (byte addresses, end exclusive).
    pub ranges: &'a [(u32, u32)],
    /// Program counter and cycle of the last stack pointer write.
    pub last_sp_write: (u32, u64),
    /// The cycle execution reached 0.
    pub arrived: u64,
    /// Z (and EIND) as they stand.
    pub z: u32,
}

impl ZeroOrigin<'_> {
    pub(crate) fn find(&self) -> Option<u32> {
        let word = |pc: u32| self.flash.get(pc as usize / 2).copied().unwrap_or(0);
        let (pc, cycle) = self.last_sp_write;
        let op = word(pc);
        let cycles = match op {
            0x9508 | 0x9518 => 5,            // ret, reti
            0x9509 | 0x9519 => 4,            // icall, eicall
            _ if op & 0xFE0E == 0x940E => 5, // call
            _ if op & 0xF000 == 0xD000 => 4, // rcall
            _ => 0,
        };
        if cycles > 0 && cycle + cycles == self.arrived {
            return Some(pc);
        }
        let flash_bytes = (self.flash.len() * 2) as i64;
        for &(start, end) in self.ranges {
            let mut a = start;
            while a < end {
                let op = word(a);
                let to_zero = match op {
                    // rjmp (the core wraps at the end of flash)
                    _ if op & 0xF000 == 0xC000 => {
                        let k = i64::from(((op & 0x0FFF) as i16) << 4 >> 4);
                        (i64::from(a) + 2 + 2 * k).rem_euclid(flash_bytes) == 0
                    }
                    // jmp
                    _ if op & 0xFE0E == 0x940C => word(a + 2) == 0 && (op & 0x01F1) == 0,
                    // brbs / brbc
                    _ if op & 0xF800 == 0xF000 => {
                        let k = (((op >> 3) & 0x7F) as i16) << 9 >> 9;
                        i64::from(a) + 2 + 2 * i64::from(k) == 0
                    }
                    0x9409 | 0x9419 => self.z == 0,
                    _ => false,
                };
                if to_zero {
                    return Some(a);
                }
                a += 2 * words(op);
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clis_are_found_on_instruction_boundaries_only() {
        // sts 0x94F8, r16 (its address word looks like cli); cli; nop; cli
        let code = [0x9300, CLI, CLI, 0x0000, CLI];
        assert_eq!(cli_sites(&code, 0x100), [0x104, 0x108]);
    }

    #[test]
    fn a_jump_to_zero_is_traced_to_its_source() {
        // nop; nop; rjmp 0
        let flash = [0, 0, 0xCFFD];
        let o = ZeroOrigin {
            flash: &flash,
            ranges: &[(0, 6)],
            last_sp_write: (0, 0),
            arrived: 5,
            z: 1,
        };
        assert_eq!(o.find(), Some(4));
        // ret at 2 whose SP write began at cycle 10, arriving at 15.
        let flash = [0, 0x9508];
        let o = ZeroOrigin {
            flash: &flash,
            ranges: &[(0, 4)],
            last_sp_write: (2, 10),
            arrived: 15,
            z: 1,
        };
        assert_eq!(o.find(), Some(2));
    }
}
