//! What a virtual card has seen: for tests and benchmarks.

/// Counters since the card was made; they survive CMD0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SdStats {
    /// Command frames received (CMDn and ACMDn), answered or not.
    pub commands: u64,
    /// Commands rejected for a bad CRC7, and written blocks for a bad CRC16.
    pub crc_errors: u64,
    pub blocks_read: u64,
    pub blocks_written: u64,
    /// Bytes clocked with the card selected.
    pub bytes_selected: u64,
    /// Bytes clocked with chip select high (power-up clocks among them).
    pub bytes_deselected: u64,
    cmd: [u32; 64],
    acmd: [u32; 64],
}

impl Default for SdStats {
    fn default() -> Self {
        SdStats {
            commands: 0,
            crc_errors: 0,
            blocks_read: 0,
            blocks_written: 0,
            bytes_selected: 0,
            bytes_deselected: 0,
            cmd: [0; 64],
            acmd: [0; 64],
        }
    }
}

impl SdStats {
    /// How often CMD`n` was received.
    pub fn cmd(&self, n: u8) -> u32 {
        self.cmd[usize::from(n & 63)]
    }

    /// How often ACMD`n` (after CMD55) was received.
    pub fn acmd(&self, n: u8) -> u32 {
        self.acmd[usize::from(n & 63)]
    }

    pub(crate) fn count(&mut self, n: u8, app: bool) {
        self.commands += 1;
        let table = if app { &mut self.acmd } else { &mut self.cmd };
        table[usize::from(n & 63)] += 1;
    }
}
