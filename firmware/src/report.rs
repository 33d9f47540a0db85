//! Figures read out over the serial console (`$Q`) and logged at the end of
//! a job: how full each queue got, what it refused, what the step interrupt
//! missed.

use crate::board::port::Port;
use crate::queues::{
    buttons_stats, card_in_stats, card_out_stats, job_control_stats, samples_stats, BLOCKS,
    SEGMENTS,
};
use crate::{flash_str, info};
use taut_logic::sched::QueueStats;

fn queue(name: crate::board::flash::FlashStr, s: QueueStats, capacity: usize) {
    info!(
        name,
        " sent:", s.sent, " refused:", s.refused, " high:", s.high_water, "/", capacity
    );
}

/// `$Q` and the end of a job: every queue that crosses a task or an
/// interrupt, then dropped log lines; line `i` of them. False past the end.
pub fn queue_line(i: u8) -> bool {
    match i {
        0 => queue(
            flash_str!("rx"),
            Port::Usb.rx_stats(),
            Port::Usb.rx_capacity(),
        ),
        1 => {
            let (stats, capacity) = Port::Usb.tx_stats();
            queue(flash_str!("tx"), stats, capacity)
        }
        2 => queue(
            flash_str!("segments"),
            SEGMENTS.stats(),
            SEGMENTS.capacity(),
        ),
        3 => queue(flash_str!("blocks"), BLOCKS.stats(), BLOCKS.capacity()),
        4 => {
            let (stats, capacity) = card_out_stats();
            queue(flash_str!("card"), stats, capacity)
        }
        5 => {
            let (stats, capacity) = card_in_stats();
            queue(flash_str!("card req"), stats, capacity)
        }
        6 => {
            let (stats, capacity) = samples_stats();
            queue(flash_str!("button samples"), stats, capacity)
        }
        7 => {
            let (stats, capacity) = buttons_stats();
            queue(flash_str!("buttons"), stats, capacity)
        }
        8 => {
            let (stats, capacity) = job_control_stats();
            queue(flash_str!("job control"), stats, capacity)
        }
        9 => queue(
            flash_str!("rx1"),
            Port::Uart1.rx_stats(),
            Port::Uart1.rx_capacity(),
        ),
        10 => {
            let (stats, capacity) = Port::Uart1.tx_stats();
            queue(flash_str!("tx1"), stats, capacity)
        }
        11 => info!("log dropped:", crate::log::dropped()),
        _ => return false,
    }
    true
}
