//! The card slot: the card in it (if any), the card a planned removal took
//! out, and the insertions, removals and faults planned for later simulated
//! times. Plain data: simavr's SPI callback hands it the bytes, the run loop
//! applies what falls due.

use super::{CardFault, SdCard};

/// A change to the slot planned for a later cycle.
pub(crate) enum Change {
    /// This card goes in, replacing any card there.
    Insert(Box<SdCard>),
    /// The card goes out, into the hand (`Reinsert` puts it back).
    Remove,
    /// The card in the hand goes back in; a card that pulled itself out
    /// mid-transfer is pushed back. Either powers up afresh.
    Reinsert,
    /// A fault for the card in the slot; with none, for the next card in.
    Fault(CardFault),
}

#[derive(Default)]
pub(crate) struct Slot {
    card: Option<SdCard>,
    /// The card a planned removal took out.
    hand: Option<SdCard>,
    /// Planned changes by cycle; same-cycle ones in the order planned.
    plan: Vec<(u64, Change)>,
    /// Faults planned while the slot was empty.
    pending: Vec<CardFault>,
}

impl Slot {
    /// One SPI byte; an empty slot leaves MISO floating high.
    pub fn exchange(&mut self, mosi: u8, cs_low: bool) -> u8 {
        match self.card.as_mut() {
            Some(card) => card.exchange(mosi, cs_low),
            None => 0xFF,
        }
    }

    pub fn card(&self) -> Option<&SdCard> {
        self.card.as_ref()
    }

    pub fn card_mut(&mut self) -> Option<&mut SdCard> {
        self.card.as_mut()
    }

    /// Puts `card` in, replacing any card there: it powers up uninitialised
    /// and gets the faults planned while the slot was empty.
    pub fn insert(&mut self, mut card: SdCard) {
        card.power_up();
        for fault in self.pending.drain(..) {
            card.inject(fault);
        }
        self.card = Some(card);
    }

    pub fn take(&mut self) -> Option<SdCard> {
        self.card.take()
    }

    /// Plans `change` for cycle `at`, after changes already planned for that
    /// cycle; applied at once when due by `now`.
    pub fn plan(&mut self, now: u64, at: u64, change: Change) {
        let index = self.plan.partition_point(|(when, _)| *when <= at);
        self.plan.insert(index, (at, change));
        self.apply_due(now);
    }

    /// Applies the changes due by cycle `now`.
    pub fn apply_due(&mut self, now: u64) {
        let due = self.plan.partition_point(|(at, _)| *at <= now);
        let changes: Vec<_> = self.plan.drain(..due).collect();
        for (_, change) in changes {
            self.apply(change);
        }
    }

    /// Cycle of the next planned change.
    pub fn next_due(&self) -> Option<u64> {
        self.plan.first().map(|(at, _)| *at)
    }

    fn apply(&mut self, change: Change) {
        match change {
            Change::Insert(card) => self.insert(*card),
            Change::Remove => {
                if let Some(card) = self.card.take() {
                    self.hand = Some(card);
                }
            }
            Change::Reinsert => match self.card.take() {
                Some(card) if card.is_pulled() => self.insert(card),
                Some(card) => self.card = Some(card),
                None => {
                    if let Some(card) = self.hand.take() {
                        self.insert(card);
                    }
                }
            },
            Change::Fault(fault) => match self.card.as_mut() {
                Some(card) => card.inject(fault),
                None => self.pending.push(fault),
            },
        }
    }
}
