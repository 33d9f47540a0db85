//! Seed 003's line protocol, the whiteboard machine's own as its maker
//! built it: `+0615-0950n` is a sign and four digits of raw steps for the
//! left motor, the same for the right, then the pen (`u` up, `n` down,
//! either case) before the move. The console reads such a line beside
//! G-code (its first character `+` or `-`); what the seed's firmware did
//! with each character, and where taut differs, is in `docs/console.md`.

/// A seed-003 line read whole.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SeedMove {
    /// Steps of the left and the right motor (channels 0 and 1), from
    /// where the moves before end: `+` is the channel's positive
    /// direction.
    pub steps: [i16; 2],
    /// `u`: the pen up before the move; `n` (*niðri*): down.
    pub pen_up: bool,
}

/// Characters of a seed line: two signs and eight digits, the pen.
pub const SEED_LINE: u8 = 11;

/// Gathers a seed line a character at a time, as the console's parser
/// hands them on (comments and line ends taken out; spaces and control
/// bytes as `b' '`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SeedBuilder {
    /// Characters taken.
    at: u8,
    /// The steps' magnitudes, then signed at `-`.
    steps: [i16; 2],
    /// Bit 0, 1: the left, right steps are negative.
    negative: u8,
    pen_up: bool,
    /// A character out of place: the line is refused (`?`).
    bad: bool,
}

impl Default for SeedBuilder {
    fn default() -> Self {
        Self::new()
    }
}

impl SeedBuilder {
    pub const fn new() -> SeedBuilder {
        SeedBuilder {
            at: 0,
            steps: [0; 2],
            negative: 0,
            pen_up: false,
            bad: false,
        }
    }

    /// The next character of the line. Spaces may only follow the pen's
    /// letter; the seed read exactly eleven characters.
    pub fn feed(&mut self, c: u8) {
        let at = self.at;
        self.at = at.saturating_add(1);
        let motor = usize::from(at >= 5);
        match (at, c) {
            (SEED_LINE.., b' ') => {}
            (0 | 5, b'+') => {}
            (0 | 5, b'-') => self.negative |= 1 << motor,
            (1..=4 | 6..=9, b'0'..=b'9') => {
                self.steps[motor] = self.steps[motor] * 10 + i16::from(c - b'0');
            }
            (10, b'u' | b'U') => self.pen_up = true,
            (10, b'n' | b'N') => self.pen_up = false,
            _ => self.bad = true,
        }
    }

    /// The line's move, or `None` when it is not one (a character out of
    /// place, too few).
    pub fn finish(&self) -> Option<SeedMove> {
        if self.bad || self.at < SEED_LINE {
            return None;
        }
        let signed = |i: usize| match self.negative >> i & 1 {
            1 => -self.steps[i],
            _ => self.steps[i],
        };
        Some(SeedMove {
            steps: [signed(0), signed(1)],
            pen_up: self.pen_up,
        })
    }
}

/// A seed line's characters (without its line end) as the console reads
/// them.
pub fn parse(line: &[u8]) -> Option<SeedMove> {
    let mut b = SeedBuilder::new();
    line.iter().for_each(|&c| b.feed(c));
    b.finish()
}

impl SeedMove {
    /// The line as the seed's host wrote it, e.g. `+0615-0950n`.
    pub fn text(&self) -> [u8; SEED_LINE as usize] {
        let mut out = [0u8; SEED_LINE as usize];
        for (i, &s) in self.steps.iter().enumerate() {
            let at = i * 5;
            out[at] = if s < 0 { b'-' } else { b'+' };
            let mut n = s.unsigned_abs();
            for d in (1..5).rev() {
                out[at + d] = b'0' + (n % 10) as u8;
                n /= 10;
            }
        }
        out[10] = if self.pen_up { b'u' } else { b'n' };
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_seeds_lines_read_as_its_firmware_read_them() {
        assert_eq!(
            parse(b"+0615-0950n"),
            Some(SeedMove {
                steps: [615, -950],
                pen_up: false
            })
        );
        assert_eq!(
            parse(b"-9999+0000U"),
            Some(SeedMove {
                steps: [-9999, 0],
                pen_up: true
            })
        );
        assert_eq!(parse(b"+0000+0000N").map(|m| m.pen_up), Some(false));
        // Trailing spaces (a file's) are no harm.
        assert!(parse(b"+0103+0022n  ").is_some());
    }

    #[test]
    fn a_malformed_line_is_none() {
        for bad in [
            &b"+0615-0950"[..],
            b"+0615-0950x",
            b"+615-0950n",
            b"+0615 -0950n",
            b"+0615-0950nn",
            b"+06a5-0950n",
            b"*0615-0950n",
            b"+0615*0950n",
            // The seed took `:` for a digit of 10 (its check was `c > 10`).
            b"+061:-0950n",
            b"",
        ] {
            assert_eq!(parse(bad), None, "{:?}", core::str::from_utf8(bad));
        }
    }

    #[test]
    fn text_reads_back() {
        for steps in [[615, -950], [-9999, 9999], [0, -1], [-1, 0]] {
            for pen_up in [false, true] {
                let m = SeedMove { steps, pen_up };
                assert_eq!(parse(&m.text()), Some(m));
            }
        }
        let m = SeedMove {
            steps: [615, -950],
            pen_up: false,
        };
        assert_eq!(&m.text(), b"+0615-0950n");
    }
}
