//! The homing switches: a plotter's MIN inputs (X_MIN D3, Y_MIN D14, Z_MIN
//! D18; switches to ground, closed reads low), read by the 1 ms tick with
//! the buttons that share them. While homing watches one, the tick stops
//! the steps at once when it closes, as Ctrl-X does: a homing leg is then
//! over wherever the switch caught it.

use crate::rt::byte;
use crate::stepper;
use core::sync::atomic::{AtomicBool, AtomicU8};
use taut_logic::axis::AXES;
use taut_logic::pinmap::Button;

/// The button bit (`1 << Button as u8`) of each channel's MIN input.
const MIN_INPUT: [u8; AXES] = [
    1 << Button::ZeroBase as u8,
    1 << Button::ZeroRadial as u8,
    1 << Button::ZeroDrill as u8,
];

/// The switch bits watched (0: none).
static WATCHED: AtomicU8 = AtomicU8::new(0);
/// The watched switch closed and the steps were stopped.
static HIT: AtomicBool = AtomicBool::new(false);
/// The tick's last reading.
static LAST: AtomicU8 = AtomicU8::new(0);

/// Stop the steps when channel `axis`'s switch closes.
pub fn watch(axis: usize) {
    byte::store_bool(&HIT, false);
    byte::store(&WATCHED, MIN_INPUT[axis]);
}

/// Whether the watched switch has stopped the steps.
pub fn hit() -> bool {
    byte::load_bool(&HIT)
}

/// Stop watching: whether the switch had stopped the steps.
pub fn disarm() -> bool {
    // No swap on the AVR: masked, so a tick cannot set it in between.
    avr_device::interrupt::free(|_| {
        byte::store(&WATCHED, 0);
        let hit = byte::load_bool(&HIT);
        byte::store_bool(&HIT, false);
        hit
    })
}

/// Channel `axis`'s switch is closed, as the last tick read it.
pub fn closed(axis: usize) -> bool {
    byte::load(&LAST) & MIN_INPUT[axis] != 0
}

/// The tick, with the inputs it read (bit = button): true when the
/// watched switch just closed (the steps are stopped; the console goes on).
pub fn on_tick(raw: u8) -> bool {
    byte::store(&LAST, raw);
    let watched = byte::load(&WATCHED);
    if watched == 0 || raw & watched == 0 {
        return false;
    }
    stepper::halt();
    byte::store(&WATCHED, 0);
    byte::store_bool(&HIT, true);
    true
}
