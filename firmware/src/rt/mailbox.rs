//! A one-slot mailbox between software tasks: the newest request waits,
//! a newer one replaces it (the reader only ever wants the last). Counted
//! like a ring (`$Q`): a replaced request counts as refused. Software
//! tasks only (a [`TaskCell`]): interrupts use a `Ring`.

use super::TaskCell;
use core::mem::MaybeUninit;
use taut_logic::sched::QueueStats;

pub struct Mailbox<T: Copy> {
    slot: TaskCell<Slot<T>>,
}

/// `full` and an uninitialised item rather than an `Option`: the empty
/// mailbox is all zeros, in `.bss` (an `Option`'s `None` tag would put it
/// in `.data`, a copy in flash).
struct Slot<T> {
    full: bool,
    item: MaybeUninit<T>,
    stats: QueueStats,
}

impl<T: Copy> Mailbox<T> {
    pub const fn new() -> Self {
        Mailbox {
            slot: TaskCell::new(Slot {
                full: false,
                item: MaybeUninit::uninit(),
                stats: QueueStats::new(),
            }),
        }
    }

    /// Sender: leave `item`, replacing the one waiting (counted refused).
    pub fn put(&self, item: T) {
        self.slot.with(|s| {
            if s.full {
                s.stats.on_refused();
            }
            s.item = MaybeUninit::new(item);
            s.full = true;
            s.stats.on_send(1);
        })
    }

    /// Receiver: the item waiting, taken.
    pub fn take(&self) -> Option<T> {
        self.slot.with(|s| {
            let item = s.get();
            s.full = false;
            item
        })
    }

    /// Receiver: the item waiting, left there.
    pub fn peek(&self) -> Option<T> {
        self.slot.with(|s| s.get())
    }

    pub fn is_empty(&self) -> bool {
        self.slot.with(|s| !s.full)
    }

    pub const fn capacity(&self) -> usize {
        1
    }

    pub fn stats(&self) -> QueueStats {
        self.slot.with(|s| s.stats)
    }
}

impl<T: Copy> Default for Mailbox<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl<T: Copy> Slot<T> {
    fn get(&self) -> Option<T> {
        // SAFETY: `full` is set only after `item` is written.
        self.full.then(|| unsafe { self.item.assume_init() })
    }
}
