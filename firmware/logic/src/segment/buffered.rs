//! How much motion the step queue holds, in time rather than segments: a
//! segment lasts from one event (≥ 2.5 ms at slow speeds, where preparing
//! it costs about as much) to 128 events (2 ms at 60 kHz). The refill is
//! urgent when the queued segments last less than a budget — not when
//! there are few of them, which at slow speeds would keep it urgent (and
//! every other task waiting) while the queue holds plenty.

use super::{Segment, FRAC_BITS, TICK_HZ};

/// Sub-ticks per µs: 16 ticks of 256.
const SUBTICKS_PER_US_SHIFT: u32 = FRAC_BITS + (TICK_HZ / 1_000_000).trailing_zeros();
const _: () = assert!(TICK_HZ / 1_000_000 == 16);

impl Segment {
    /// Time from the event before the segment to its last event, µs
    /// (saturating at 65.5 ms).
    pub fn duration_us(&self) -> u16 {
        let n = u32::from(self.count);
        // A cruise (no `add`) in 32-bit arithmetic: cheap on the AVR.
        let cruise = (self.interval >> SUBTICKS_PER_US_SHIFT).saturating_mul(n);
        let us = if self.add == 0 {
            i64::from(cruise)
        } else {
            let sub = i64::from(self.interval) * i64::from(n)
                + i64::from(self.add) * i64::from(n * (n - 1) / 2);
            sub.max(0) >> SUBTICKS_PER_US_SHIFT
        };
        us.min(u16::MAX as i64) as u16
    }
}

/// Units of [`Buffered`]'s memory: 250 µs, a byte a segment.
const UNIT_US: u16 = 250;

/// The durations of the last `N` segments queued (`N` ≥ the queue's
/// capacity, so every queued segment is among them), in 250 µs units
/// (saturating at 63.75 ms): a byte each.
pub struct Buffered<const N: usize> {
    units: [u8; N],
    next: usize,
}

impl<const N: usize> Default for Buffered<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> Buffered<N> {
    pub const fn new() -> Self {
        Buffered {
            units: [0; N],
            next: 0,
        }
    }

    pub fn push(&mut self, seg: &Segment) {
        self.units[self.next] = (seg.duration_us() / UNIT_US).min(u8::MAX as u16) as u8;
        self.next = (self.next + 1) % N;
    }

    /// How long the newest `len` segments last, µs (the queue's motion
    /// when `len` is its length).
    pub fn queued_us(&self, len: usize) -> u32 {
        (0..len.min(N))
            .map(|back| u32::from(self.units[(self.next + N - 1 - back) % N]))
            .sum::<u32>()
            * u32::from(UNIT_US)
    }

    /// Whether the newest `len` segments last `us` or more: as
    /// `queued_us(len) >= us`, counting only as far as it must (the
    /// firmware asks at every run of its console and segment preparation).
    /// Inlined: `us` is a constant, its division made when compiling.
    #[inline(always)]
    pub fn lasts(&self, len: usize, us: u32) -> bool {
        let want = us.div_ceil(u32::from(UNIT_US));
        let mut total = 0u32;
        let mut at = self.next;
        for _ in 0..len.min(N) {
            at = if at == 0 { N - 1 } else { at - 1 };
            total += u32::from(self.units[at]);
            if total >= want {
                return true;
            }
        }
        want == 0
    }

    /// The queue is short when it holds this many segments or fewer: the
    /// newest segments, counted back until they last `budget_us` (the
    /// oldest queued go first, so the queue then holds less than that).
    pub fn short_at(&self, budget_us: u32) -> usize {
        let mut total = 0u32;
        for back in 0..N {
            total += u32::from(self.units[(self.next + N - 1 - back) % N]) * u32::from(UNIT_US);
            if total >= budget_us {
                return back;
            }
        }
        N
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seg(interval_us: u32, count: u16, add: i32) -> Segment {
        Segment {
            interval: interval_us << SUBTICKS_PER_US_SHIFT,
            add,
            count,
            flags: 0,
        }
    }

    #[test]
    fn a_segment_lasts_its_intervals() {
        assert_eq!(seg(2500, 1, 0).duration_us(), 2500);
        assert_eq!(seg(100, 128, 0).duration_us(), 12_800);
        // Intervals 1000, 999, 998 µs: add = −1 µs.
        let slowing = seg(1000, 3, -(1 << SUBTICKS_PER_US_SHIFT));
        assert_eq!(slowing.duration_us(), 2997);
        assert_eq!(seg(60_000, 2, 0).duration_us(), u16::MAX);
    }

    #[test]
    fn short_when_the_newest_segments_last_less_than_the_budget() {
        let mut b = Buffered::<8>::new();
        assert_eq!(b.short_at(30_000), 8, "nothing queued: always short");
        for _ in 0..10 {
            b.push(&seg(2000, 1, 0));
        }
        // The eight remembered 2 ms segments make 16 ms: short at any length.
        assert_eq!(b.short_at(30_000), 8);
        assert_eq!(b.short_at(10_000), 4);
        b.push(&seg(25_000, 1, 0));
        // The newest alone lasts 25 ms, with the next 27 ms, …, 31 ms.
        assert_eq!(b.short_at(30_000), 3);
        assert_eq!(b.short_at(20_000), 0);
        assert_eq!(b.queued_us(3), 25_000 + 2 * 2000);
        assert_eq!(b.queued_us(100), 25_000 + 7 * 2000, "at most N remembered");
        for (len, us) in [
            (0, 0),
            (0, 1),
            (1, 25_000),
            (1, 25_001),
            (3, 29_000),
            (3, 29_001),
            (100, 39_000),
            (100, 39_001),
        ] {
            assert_eq!(b.lasts(len, us), b.queued_us(len) >= us, "{len} {us}");
        }
    }
}
