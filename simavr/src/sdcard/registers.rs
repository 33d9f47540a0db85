//! The card's registers as the host reads them: OCR (CMD58), CSD (CMD9),
//! CID (CMD10). The CSD is computed from the image size, so the capacity the
//! host reads matches the image.

use super::crc::crc7;

/// OCR voltage window 2.7–3.6 V (bits 23..15).
const OCR_VOLTAGES: u32 = 0x00FF_8000;
/// Power-up finished.
const OCR_READY: u32 = 1 << 31;
/// Card capacity status: block addressing (SDHC/SDXC).
const OCR_CCS: u32 = 1 << 30;

pub fn ocr(ready: bool, sdhc: bool) -> u32 {
    match (ready, sdhc) {
        (false, _) => OCR_VOLTAGES,
        (true, false) => OCR_VOLTAGES | OCR_READY,
        (true, true) => OCR_VOLTAGES | OCR_READY | OCR_CCS,
    }
}

/// Sets `width` bits ending at bit `low` of a 128-bit register.
fn field(reg: &mut u128, low: u32, width: u32, value: u32) {
    let mask = (1u128 << width) - 1;
    *reg |= (u128::from(value) & mask) << low;
}

/// The 16 bytes of a register, CRC7 and end bit in the last.
fn with_crc(reg: u128) -> [u8; 16] {
    let mut bytes = reg.to_be_bytes();
    bytes[15] = crc7(&bytes[..15]) << 1 | 1;
    bytes
}

/// Fields common to both CSD versions: 25 MHz, command classes 0, 2, 4, 5,
/// 7, 8, 10, 512-byte blocks, single-block erase, write speed factor 4.
fn csd_common(version: u32) -> u128 {
    let mut reg = 0;
    field(&mut reg, 126, 2, version);
    field(&mut reg, 112, 8, 0x0E); // TAAC: 1 ms
    field(&mut reg, 96, 8, 0x32); // TRAN_SPEED: 25 MHz
    field(&mut reg, 84, 12, 0x5B5); // CCC
    field(&mut reg, 80, 4, 9); // READ_BL_LEN: 512
    field(&mut reg, 46, 1, 1); // ERASE_BLK_EN
    field(&mut reg, 39, 7, 0x7F); // SECTOR_SIZE: 128 blocks
    field(&mut reg, 26, 3, 2); // R2W_FACTOR
    field(&mut reg, 22, 4, 9); // WRITE_BL_LEN: 512
    reg
}

/// CSD version 2 (SDHC): capacity in units of 512 KiB. Returns the register
/// and the capacity in blocks it states.
pub fn csd_v2(min_blocks: u32) -> ([u8; 16], u32) {
    let units = min_blocks.div_ceil(1024).max(1);
    let mut reg = csd_common(1);
    field(&mut reg, 48, 22, units - 1); // C_SIZE
    (with_crc(reg), units * 1024)
}

/// CSD version 1 (SDSC): (C_SIZE + 1) << (C_SIZE_MULT + 2) blocks of
/// 2^READ_BL_LEN bytes. Returns the register and its capacity in 512-byte
/// blocks; images past 4 GiB cannot be described.
pub fn csd_v1(min_blocks: u32) -> Option<([u8; 16], u32)> {
    // The largest block length and multiplier are used only when the
    // 12-bit C_SIZE cannot count the image otherwise.
    for read_bl_len in 9..=11u32 {
        for mult in 0..=7u32 {
            let shift = mult + 2 + read_bl_len - 9;
            let units = min_blocks.div_ceil(1 << shift).max(1);
            if units <= 4096 {
                let mut reg = csd_common(0);
                reg &= !(0xF << 80);
                field(&mut reg, 80, 4, read_bl_len);
                field(&mut reg, 62, 12, units - 1); // C_SIZE
                field(&mut reg, 59, 3, 7); // VDD_R_CURR_MIN
                field(&mut reg, 56, 3, 6); // VDD_R_CURR_MAX
                field(&mut reg, 53, 3, 7); // VDD_W_CURR_MIN
                field(&mut reg, 50, 3, 6); // VDD_W_CURR_MAX
                field(&mut reg, 47, 3, mult); // C_SIZE_MULT
                return Some((with_crc(reg), units << shift));
            }
        }
    }
    None
}

/// A fixed CID: manufacturer 0x54, OEM "TA", product "TAUT1", revision 1.0,
/// serial 0x5D000001, made January 2025.
pub fn cid() -> [u8; 16] {
    let mut reg = 0;
    field(&mut reg, 120, 8, 0x54);
    field(&mut reg, 104, 16, u32::from(u16::from_be_bytes(*b"TA")));
    for (i, &c) in b"TAUT1".iter().enumerate() {
        field(&mut reg, 96 - 8 * i as u32, 8, u32::from(c));
    }
    field(&mut reg, 56, 8, 0x10);
    field(&mut reg, 24, 32, 0x5D00_0001);
    field(&mut reg, 8, 12, (25 << 4) | 1);
    with_crc(reg)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Capacity in 512-byte blocks as a host computes it from a CSD.
    fn host_capacity(csd: &[u8; 16]) -> u64 {
        let reg = u128::from_be_bytes(*csd);
        let bits = |low: u32, width: u32| ((reg >> low) & ((1 << width) - 1)) as u64;
        match bits(126, 2) {
            0 => (bits(62, 12) + 1) << (bits(47, 3) + 2 + bits(80, 4) - 9),
            1 => (bits(48, 22) + 1) * 1024,
            v => panic!("CSD structure {v}"),
        }
    }

    #[test]
    fn csd_capacity_covers_the_image() {
        for blocks in [1, 1000, 16_384, 65_536, 4_194_304, 8_388_608] {
            let (csd, cap) = csd_v1(blocks).unwrap();
            assert!(u64::from(cap) >= u64::from(blocks));
            assert_eq!(host_capacity(&csd), u64::from(cap), "v1 {blocks}");
            let (csd, cap) = csd_v2(blocks);
            assert!(cap >= blocks && cap - blocks < 1024);
            assert_eq!(host_capacity(&csd), u64::from(cap), "v2 {blocks}");
        }
        assert_eq!(csd_v1(16_384).unwrap().1, 16_384, "8 MiB exactly");
        assert!(csd_v1(u32::MAX).is_none());
    }

    #[test]
    fn registers_end_in_their_crc7() {
        for reg in [cid(), csd_v2(100).0, csd_v1(100).unwrap().0] {
            assert_eq!(reg[15], crc7(&reg[..15]) << 1 | 1);
        }
    }

    #[test]
    fn ocr_states() {
        assert_eq!(ocr(false, true) >> 30, 0);
        assert_eq!(ocr(true, false) >> 30, 0b10);
        assert_eq!(ocr(true, true) >> 30, 0b11);
    }
}
