//! What the step interrupt does with the segments, replayed on the host:
//! the reference the HIL tests and the benchmark compare against.

use super::{Segment, StepBlock, FRAC_BITS, NEW_BLOCK};
use crate::axis::{PerAxis, AXES};

/// One step event.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Event {
    /// Step-timer (Timer3) tick of the event (the compare match), counted from 0.
    pub tick: u64,
    /// Bit `i`: axis `i` steps.
    pub axes: u8,
    /// The block's direction bits ([`StepBlock::dir`]).
    pub dir: u8,
}

/// Iterator over the events of a segment stream; see [`expand`].
pub struct Expand<S, B> {
    segments: S,
    blocks: B,
    block: StepBlock,
    counter: PerAxis<u32>,
    /// 24.8 fixed-point time of the last event, sub-ticks.
    time: u64,
    interval: u32,
    add: i32,
    left: u16,
}

/// Replays the interrupt: per event `time += interval; interval += add`,
/// then the DDA — each axis adds its step count to its counter and steps
/// when the counter reaches the block's event count. A segment flagged
/// [`NEW_BLOCK`] first takes the next block and resets the counters to
/// `events / 2`. The event fires at the integer part of `time`.
pub fn expand<S, B>(segments: S, blocks: B) -> Expand<S::IntoIter, B::IntoIter>
where
    S: IntoIterator<Item = Segment>,
    B: IntoIterator<Item = StepBlock>,
{
    Expand {
        segments: segments.into_iter(),
        blocks: blocks.into_iter(),
        block: StepBlock::default(),
        counter: [0; AXES],
        time: 0,
        interval: 0,
        add: 0,
        left: 0,
    }
}

impl<S, B> Iterator for Expand<S, B>
where
    S: Iterator<Item = Segment>,
    B: Iterator<Item = StepBlock>,
{
    type Item = Event;

    fn next(&mut self) -> Option<Event> {
        while self.left == 0 {
            let seg = self.segments.next()?;
            if seg.flags & NEW_BLOCK != 0 {
                self.block = self.blocks.next()?;
                self.counter = [self.block.events / 2; AXES];
            }
            self.interval = seg.interval;
            self.add = seg.add;
            self.left = seg.count;
        }
        self.time += self.interval as u64;
        self.interval = self.interval.wrapping_add(self.add as u32);
        self.left -= 1;
        let mut axes = 0;
        for (i, c) in self.counter.iter_mut().enumerate() {
            *c += self.block.steps[i];
            if *c >= self.block.events {
                *c -= self.block.events;
                axes |= 1 << i;
            }
        }
        Some(Event {
            tick: self.time >> FRAC_BITS,
            axes,
            dir: self.block.dir,
        })
    }
}
