//! No function of the image takes arguments on the stack.
//!
//! The AVR calling convention passes 18 bytes of arguments in registers
//! (r25 down to r8; a result wider than 8 bytes takes 2 of them for its
//! pointer); the rest go on the stack. LLVM's AVR back end reads stack
//! arguments one byte off on the ATmega2560: its calls push a 3-byte
//! return address, and the callee's offsets assume 2. A function called
//! so reads its last argument shifted by a byte (the cruise of a
//! trapezoid once ran at 54 000 steps/s for it). Whether a function gets
//! stack arguments depends on inlining, so a change anywhere can make one:
//! the check reads the image.
//!
//! A callee with a frame sets Y to its stack pointer after pushing the
//! registers it saves (`push` ×p, `in r28/r29`, `sbiw r28, f` or
//! `subi/sbci`); its locals are `Y+1..=Y+f`, the saved registers above
//! them, then the return address, then the caller's stack arguments. Any
//! `ldd Rd, Y+q` with `q > f + p` (Y unchanged since) reads past the
//! saved registers: a stack argument.

/// Functions (name, first such offset) that read stack arguments, from
/// the code bytes of each function `(name, start, bytes)`.
pub fn readers<'a>(functions: impl Iterator<Item = (&'a str, &'a [u8])>) -> Vec<(String, u8)> {
    functions
        .filter_map(|(name, code)| first_stack_read(code).map(|q| (name.to_string(), q)))
        .collect()
}

/// The first `ldd Rd, Y+q` past the frame and the saved registers, if
/// the function sets up a frame in its prologue.
fn first_stack_read(code: &[u8]) -> Option<u8> {
    let words: Vec<u16> = code
        .chunks_exact(2)
        .map(|w| u16::from_le_bytes([w[0], w[1]]))
        .collect();
    let (mut pushes, mut frame, mut low, mut y_read) = (0u32, None::<u32>, None::<u32>, false);
    let mut i = 0;
    while i < words.len() {
        let w = words[i];
        i += 1 + usize::from(two_words(w));
        if frame.is_none() {
            if w & 0xFE0F == 0x920F {
                pushes += 1;
                continue;
            } else if w == IN_R28_SPL || w == IN_R29_SPH {
                y_read = true;
                continue;
            } else if let Some(k) = sbiw_y(w) {
                frame = Some(k);
                continue;
            } else if let Some(k) = imm_on(w, 0x5000, 28) {
                low = Some(k);
                continue;
            } else if let (Some(lo), Some(hi)) = (low, imm_on(w, 0x4000, 29)) {
                frame = Some(lo + 256 * hi);
                continue;
            } else if y_read {
                // Y is the stack pointer, with no locals below it.
                frame = Some(0);
            } else if i > 48 {
                // No frame set up in the prologue.
                return None;
            } else {
                continue;
            }
        }
        let f = frame.unwrap_or(0);
        // Y moved: offsets no longer count from the frame.
        if sbiw_y(w).is_some()
            || adiw_y(w)
            || imm_on(w, 0x5000, 28).is_some()
            || imm_on(w, 0x4000, 29).is_some()
        {
            return None;
        }
        if let Some(q) = ldd_y(w) {
            if u32::from(q) > f + pushes {
                return Some(q);
            }
        }
    }
    None
}

/// `in r28, 0x3d` and `in r29, 0x3e`: Y from the stack pointer.
const IN_R28_SPL: u16 = 0xB7CD;
const IN_R29_SPH: u16 = 0xB7DE;

/// `call`, `jmp`, `lds`, `sts`: a second word follows.
fn two_words(w: u16) -> bool {
    w & 0xFE0C == 0x940C || w & 0xFC0F == 0x9000
}

/// `sbiw r28, K`: 1001 0111 KKdd KKKK with dd = 10 (r28).
fn sbiw_y(w: u16) -> Option<u32> {
    (w & 0xFF30 == 0x9720).then(|| u32::from(((w >> 2) & 0x30) | (w & 0x0F)))
}

/// `adiw r28, K`.
fn adiw_y(w: u16) -> bool {
    w & 0xFF30 == 0x9620
}

/// `subi`/`sbci` (`op`) with register `reg` (r16..r31): its immediate.
fn imm_on(w: u16, op: u16, reg: u16) -> Option<u32> {
    (w & 0xF000 == op && (w >> 4) & 0x0F == reg - 16)
        .then(|| u32::from(((w >> 4) & 0xF0) | (w & 0x0F)))
}

/// `ldd Rd, Y+q`: 10q0 qq0d dddd 1qqq (q > 0; q = 0 is `ld Rd, Y`).
fn ldd_y(w: u16) -> Option<u8> {
    if w & 0xD208 != 0x8008 {
        return None;
    }
    let q = ((w >> 8) & 0x20) | ((w >> 7) & 0x18) | (w & 0x07);
    (q > 0).then_some(q as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bytes(words: &[u16]) -> Vec<u8> {
        words.iter().flat_map(|w| w.to_le_bytes()).collect()
    }

    /// The prologue of the miscompiled `cruise_span`: 18 pushes, a
    /// 20-byte frame, then `ldd r10, Y+41` (its first stack argument).
    #[test]
    fn a_read_past_the_saved_registers_is_a_stack_argument() {
        let push = |r: u16| 0x920F | (r << 4);
        let mut code: Vec<u16> = (2..18).chain([28, 29]).map(push).collect();
        // in r28, 0x3d; in r29, 0x3e; sbiw r28, 20.
        code.extend([0xB7CD, 0xB7DE, 0x9764]);
        // ldd r24, Y+20 (a local), call (two words), ldd r10, Y+41.
        let ldd =
            |d: u16, q: u16| 0x8008 | (d << 4) | ((q & 0x20) << 8) | ((q & 0x18) << 7) | (q & 7);
        code.extend([ldd(24, 20), 0x940E, 0x1234, ldd(10, 41)]);
        assert_eq!(sbiw_y(0x9764), Some(20));
        assert_eq!(ldd_y(ldd(10, 41)), Some(41));
        assert_eq!(first_stack_read(&bytes(&code)), Some(41));
        // Within the frame and the saved registers: none.
        let n = code.len();
        code[n - 1] = ldd(10, 38);
        assert_eq!(first_stack_read(&bytes(&code)), None);
        // Y moved after the prologue (adiw r28, 1): not judged.
        code[n - 1] = 0x9621;
        code.push(ldd(10, 41));
        assert_eq!(first_stack_read(&bytes(&code)), None);
        let found = readers([("f", &bytes(&code)[..])].into_iter());
        assert!(found.is_empty());
    }

    /// A large frame set with `subi r28, lo` / `sbci r29, hi`.
    #[test]
    fn a_large_frame_counts_both_bytes() {
        // push r28; push r29; subi r28, 0x2C; sbci r29, 0x01 (300 B).
        let code = [0x93CF, 0x93DF, 0xB7CD, 0xB7DE, 0x52CC, 0x40D1, 0xAD8F];
        assert_eq!(imm_on(0x52CC, 0x5000, 28), Some(0x2C));
        assert_eq!(imm_on(0x40D1, 0x4000, 29), Some(1));
        // ldd r24, Y+63: inside the 300-byte frame.
        assert_eq!(first_stack_read(&bytes(&code)), None);
        // No locals: Y is the stack pointer; Y+3 past 2 saved registers.
        let code = [0x93CF, 0x93DF, 0xB7CD, 0xB7DE, 0x818B];
        assert_eq!(ldd_y(0x818B), Some(3));
        assert_eq!(first_stack_read(&bytes(&code)), Some(3));
    }
}
