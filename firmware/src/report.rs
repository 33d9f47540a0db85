//! Figures read out over the serial console (`$Q`) and logged at the end of
//! a job: how full each queue got, what it refused, what the step interrupt
//! missed.

use crate::board::usart;
use crate::stepper::{BLOCKS, SEGMENTS};
use crate::{flash_str, info};
use taut_logic::sched::QueueStats;

fn queue(name: crate::board::flash::FlashStr, s: QueueStats, capacity: usize) {
    info!(
        name,
        " sent:", s.sent, " refused:", s.refused, " high:", s.high_water, "/", capacity
    );
}

/// `$Q`: every queue that crosses an interrupt, plus dropped log lines.
pub fn queues() {
    queue(flash_str!("rx"), usart::RX.stats(), usart::RX.capacity());
    queue(flash_str!("tx"), usart::TX.stats(), usart::TX.capacity());
    queue(
        flash_str!("segments"),
        SEGMENTS.stats(),
        SEGMENTS.capacity(),
    );
    queue(flash_str!("blocks"), BLOCKS.stats(), BLOCKS.capacity());
    info!("log dropped:", crate::log::dropped());
}
