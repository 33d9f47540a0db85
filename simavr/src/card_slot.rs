//! The card slot on the simulated SPI bus, as `Sim` methods: cards in and
//! out now or at a later simulated time, faults, counters. Planned changes
//! happen at their exact cycle, between two instructions; only SPI traffic
//! can observe the slot.

use crate::clock::cycles_in;
use crate::sdcard::slot::Change;
use crate::sdcard::{CardFault, SdCard, SdStats};
use crate::sim::Sim;
use std::time::Duration;

impl Sim {
    /// Puts a card (or a bare image, as a default card) in the slot now,
    /// replacing any card there. It starts powered but uninitialised.
    pub fn insert_sd(&mut self, card: impl Into<SdCard>) {
        self.sd_slot_mut().insert(card.into());
    }

    /// Takes the card out now; it keeps what was written to it.
    pub fn remove_sd(&mut self) -> Option<SdCard> {
        self.sd_slot_mut().take()
    }

    /// Plans an insertion at simulated time `at` since power-on.
    pub fn sd_insert_at(&mut self, at: Duration, card: impl Into<SdCard>) {
        self.plan_sd(at, Change::Insert(Box::new(card.into())));
    }

    /// Plans a removal at simulated time `at` since power-on: from then on
    /// MISO floats high, as with an empty slot. The card is kept for
    /// `sd_reinsert_at`.
    pub fn sd_remove_at(&mut self, at: Duration) {
        self.plan_sd(at, Change::Remove);
    }

    /// Plans putting back, at simulated time `at`, the same card a planned
    /// removal took out (its image, counters and untriggered faults kept),
    /// or pushing back a card that pulled itself out mid-transfer. It powers
    /// up uninitialised, as a card does when it goes in.
    pub fn sd_reinsert_at(&mut self, at: Duration) {
        self.plan_sd(at, Change::Reinsert);
    }

    /// Plans a fault for the card in the slot at simulated time `at` (with
    /// the slot empty then: for the next card put in). `CardFault::CrcNext`
    /// at a time is "the first data block sent after that time has a bad
    /// CRC".
    pub fn sd_fault_at(&mut self, at: Duration, fault: CardFault) {
        self.plan_sd(at, Change::Fault(fault));
    }

    /// The card in the slot now (not one that pulled itself out).
    pub fn sd_present(&self) -> bool {
        self.sd_card().is_some_and(|card| !card.is_pulled())
    }

    /// The card in the slot now, even one that pulled itself out.
    pub fn sd_card(&self) -> Option<&SdCard> {
        self.shared().sd.card()
    }

    /// The card in the slot now, to inject faults or look at its image.
    pub fn sd_card_mut(&mut self) -> Option<&mut SdCard> {
        self.sd_slot_mut().card_mut()
    }

    /// Counters of the card in the slot now.
    pub fn sd_stats(&self) -> Option<SdStats> {
        self.sd_card().map(|card| *card.stats())
    }

    fn plan_sd(&mut self, at: Duration, change: Change) {
        let now = self.cycles();
        self.sd_slot_mut().plan(now, cycles_in(at), change);
    }
}
