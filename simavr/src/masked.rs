//! How long interrupts stay masked: every span from the I flag going off
//! to it coming back on, by the address the span began at.

/// Interrupt-masked spans by the address they began at (the vector for an
/// interrupt entry, the instruction after `cli` otherwise).
#[derive(Default)]
pub(crate) struct MaskedSpans {
    /// Start cycle and address of the span under way.
    open: Option<(u64, u32)>,
    /// Longest span per start address.
    longest: Vec<(u64, u32)>,
    /// Per start address: number of spans and their total cycles.
    totals: Vec<(u32, u64, u64)>,
    /// Interrupts were enabled once: start-up (masked from reset) is over.
    started: bool,
    /// Start address -> its index in `longest` and `totals` (the same).
    index: std::collections::HashMap<u32, usize>,
}

impl MaskedSpans {
    /// Called after every instruction with the I flag.
    pub(crate) fn observe(&mut self, cycle: u64, pc: u32, enabled: bool) {
        if !self.started {
            self.started = enabled;
            return;
        }
        match (self.open, enabled) {
            (None, false) => self.open = Some((cycle, pc)),
            (Some((start, at)), true) => {
                self.open = None;
                let len = cycle - start;
                match self.index.get(&at) {
                    Some(&i) => {
                        let (e, t) = (&mut self.longest[i], &mut self.totals[i]);
                        e.0 = e.0.max(len);
                        t.1 += 1;
                        t.2 += len;
                    }
                    None => {
                        self.index.insert(at, self.longest.len());
                        self.longest.push((len, at));
                        self.totals.push((at, 1, len));
                    }
                }
            }
            _ => {}
        }
    }

    /// The longest span not begun at `exempt`: (cycles, start address).
    pub(crate) fn longest_except(&self, exempt: u32) -> (u64, u32) {
        self.longest
            .iter()
            .filter(|(_, pc)| *pc != exempt)
            .fold(
                (0, 0),
                |best, &(c, pc)| if c > best.0 { (c, pc) } else { best },
            )
    }

    /// Spans begun at `pc`: (count, mean cycles, longest cycles).
    pub(crate) fn stats(&self, pc: u32) -> Option<(u64, f64, u64)> {
        let &(_, n, total) = self.totals.iter().find(|t| t.0 == pc)?;
        let &(max, _) = self.longest.iter().find(|l| l.1 == pc)?;
        Some((n, total as f64 / n as f64, max))
    }

    /// The longest span per start address, longest first.
    pub(crate) fn by_length(&self) -> Vec<(u64, u32)> {
        let mut v = self.longest.clone();
        v.sort_unstable_by(|a, b| b.cmp(a));
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_count_from_the_first_enable_and_keep_the_longest_per_start() {
        let mut m = MaskedSpans::default();
        m.observe(0, 0, false); // start-up: masked from reset
        m.observe(10, 2, true);
        m.observe(20, 0x44, false);
        m.observe(50, 0x60, true);
        m.observe(60, 0x44, false);
        m.observe(70, 0x62, true);
        m.observe(80, 0x100, false);
        m.observe(81, 0x102, false);
        m.observe(85, 0x104, true);
        assert_eq!(m.longest, [(30, 0x44), (5, 0x100)]);
        assert_eq!(m.totals, [(0x44, 2, 40), (0x100, 1, 5)]);
        assert_eq!(m.open, None);
        assert_eq!(m.longest_except(0x44), (5, 0x100));
        assert_eq!(m.stats(0x44), Some((2, 20.0, 30)));
        assert_eq!(m.by_length()[0], (30, 0x44));
    }
}
