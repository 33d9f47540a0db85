//! The two checksums of SPI-mode SD: CRC7 closes every command frame and the
//! CSD/CID registers, CRC16 (CCITT, XMODEM flavour) follows every data block.

/// CRC7 (polynomial x^7 + x^3 + 1) of `data`, in the low seven bits.
pub fn crc7(data: &[u8]) -> u8 {
    let mut crc = 0u8;
    for &byte in data {
        for bit in (0..8).rev() {
            let feedback = ((byte >> bit) & 1) ^ (crc >> 6);
            crc = (crc << 1) & 0x7F;
            if feedback != 0 {
                crc ^= 0x09;
            }
        }
    }
    crc
}

/// CRC16 (polynomial 0x1021, initial value 0) of `data`.
pub fn crc16(data: &[u8]) -> u16 {
    let mut crc = 0u16;
    for &byte in data {
        crc ^= u16::from(byte) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 {
                (crc << 1) ^ 0x1021
            } else {
                crc << 1
            };
        }
    }
    crc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn command_frames_from_the_specification() {
        // CMD0 with argument 0 ends in 0x95; CMD8 with 0x1AA ends in 0x87.
        assert_eq!(crc7(&[0x40, 0, 0, 0, 0]) << 1 | 1, 0x95);
        assert_eq!(crc7(&[0x48, 0, 0, 0x01, 0xAA]) << 1 | 1, 0x87);
        // CMD17 at address 0 (an example of the simplified specification).
        assert_eq!(crc7(&[0x51, 0, 0, 0, 0]) << 1 | 1, 0x55);
    }

    #[test]
    fn data_block_of_0xff_bytes() {
        // 512 bytes of 0xFF give 0x7FA1 (simplified specification, 4.5).
        assert_eq!(crc16(&[0xFF; 512]), 0x7FA1);
        assert_eq!(crc16(b"123456789"), 0x31C3);
    }
}
