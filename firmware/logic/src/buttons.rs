//! Debouncing of the machine's four buttons, sampled every millisecond by
//! the firmware's tick. Input: the raw levels as a bitmask, bit
//! `Button as u8` set while pressed (the firmware inverts the active-low
//! pins). A level counts once it has held for [`DEBOUNCE_MS`]; contacts
//! bouncing faster than that change nothing until they settle, so one
//! press is one `Pressed` however much it bounces.
//!
//! How the job reads the events: the white zeroing buttons act on
//! `Pressed`; the green button acts on `Released` with `held_ms` below
//! [`LONG_PRESS_MS`] (a short press) or on `LongPress` (sent once, 2 s into
//! the press). A long press therefore never also counts as a short one.
//!
//! Per tick: four compares and counter bumps, no division.

use crate::pinmap::Button;

/// A level must hold this long to count, ms.
pub const DEBOUNCE_MS: u8 = 20;
/// A press held this long is a long press, ms.
pub const LONG_PRESS_MS: u16 = 2000;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ButtonEvent {
    Pressed(Button),
    /// `held_ms`: since `Pressed` (saturates at 65535).
    Released {
        button: Button,
        held_ms: u16,
    },
    /// Once per press, when it has been held [`LONG_PRESS_MS`].
    LongPress(Button),
}

impl ButtonEvent {
    /// `button` was released before its press became long.
    pub fn is_short_press(self, button: Button) -> bool {
        matches!(self, ButtonEvent::Released { button: b, held_ms } if b == button && held_ms < LONG_PRESS_MS)
    }
}

/// What one tick found: at most one event per button.
pub type ButtonEvents = heapless::Vec<ButtonEvent, 4>;

/// The debouncer of the four buttons: raw samples in, events out.
pub struct Debouncer {
    /// Debounced levels, one bit per button.
    stable: u8,
    /// Consecutive ms the raw level has differed from the stable one.
    differing: [u8; 4],
    /// Ms since each button's `Pressed`.
    held: [u16; 4],
}

impl Default for Debouncer {
    fn default() -> Self {
        Self::new()
    }
}

impl Debouncer {
    /// All buttons released.
    pub const fn new() -> Self {
        Debouncer {
            stable: 0,
            differing: [0; 4],
            held: [0; 4],
        }
    }

    /// Debounced levels, bit per button.
    pub fn pressed(&self) -> u8 {
        self.stable
    }

    /// One millisecond's sample.
    pub fn tick(&mut self, raw: u8) -> ButtonEvents {
        let mut events = ButtonEvents::new();
        for button in Button::ALL {
            let i = button as usize;
            let bit = 1u8 << i;
            let was_pressed = self.stable & bit != 0;
            if (raw & bit != 0) == was_pressed {
                self.differing[i] = 0;
            } else {
                self.differing[i] += 1;
            }
            if was_pressed {
                // Saturating, so the long press is sent exactly once.
                self.held[i] = self.held[i].saturating_add(1);
            }
            let event = if self.differing[i] >= DEBOUNCE_MS {
                self.differing[i] = 0;
                self.stable ^= bit;
                if was_pressed {
                    Some(ButtonEvent::Released {
                        button,
                        held_ms: self.held[i],
                    })
                } else {
                    self.held[i] = 0;
                    Some(ButtonEvent::Pressed(button))
                }
            } else if was_pressed {
                (self.held[i] == LONG_PRESS_MS).then_some(ButtonEvent::LongPress(button))
            } else {
                None
            };
            if let Some(e) = event {
                // Four buttons, four slots: never full.
                let _ = events.push(e);
            }
        }
        events
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::vec::Vec;

    const GREEN: u8 = 1 << Button::Confirm as u8;
    const BASE: u8 = 1 << Button::ZeroBase as u8;

    /// Feeds `(level, ms)` runs; returns the events with the ms they came at.
    fn run(b: &mut Debouncer, runs: &[(u8, u32)]) -> Vec<(u32, ButtonEvent)> {
        let mut t = 0;
        let mut out = Vec::new();
        for &(level, ms) in runs {
            for _ in 0..ms {
                t += 1;
                out.extend(b.tick(level).into_iter().map(|e| (t, e)));
            }
        }
        out
    }

    #[test]
    fn clean_short_press() {
        let mut b = Debouncer::new();
        let ev = run(&mut b, &[(0, 10), (GREEN, 150), (0, 100)]);
        assert_eq!(
            ev,
            [
                (30, ButtonEvent::Pressed(Button::Confirm)),
                (
                    180,
                    ButtonEvent::Released {
                        button: Button::Confirm,
                        held_ms: 150
                    }
                )
            ]
        );
        assert!(ev[1].1.is_short_press(Button::Confirm));
        assert!(!ev[1].1.is_short_press(Button::ZeroBase));
    }

    #[test]
    fn bounce_is_one_press_and_one_release() {
        let mut b = Debouncer::new();
        let mut runs = Vec::new();
        // 40 ms of contact bounce (3 ms on, 2 ms off), held, then 30 ms of
        // bounce on release.
        runs.extend((0..8).flat_map(|_| [(BASE, 3), (0, 2)]));
        runs.push((BASE, 300));
        runs.extend((0..6).flat_map(|_| [(0, 4), (BASE, 1)]));
        runs.push((0, 100));
        let ev = run(&mut b, &runs);
        assert_eq!(ev.len(), 2, "{ev:?}");
        assert_eq!(ev[0], (40 + 20, ButtonEvent::Pressed(Button::ZeroBase)));
        assert!(matches!(
            ev[1].1,
            ButtonEvent::Released {
                button: Button::ZeroBase,
                ..
            }
        ));
        assert_eq!(b.pressed(), 0);
    }

    #[test]
    fn a_glitch_shorter_than_the_debounce_time_is_ignored() {
        let mut b = Debouncer::new();
        assert!(run(&mut b, &[(GREEN, 19), (0, 100)]).is_empty());
        // And while held, a 19 ms drop does not release it.
        let ev = run(&mut b, &[(GREEN, 100), (0, 19), (GREEN, 100)]);
        assert_eq!(ev, [(20, ButtonEvent::Pressed(Button::Confirm))]);
    }

    #[test]
    fn long_press_once_then_a_long_release() {
        let mut b = Debouncer::new();
        let ev = run(&mut b, &[(GREEN, 5000), (0, 50)]);
        assert_eq!(
            ev,
            [
                (20, ButtonEvent::Pressed(Button::Confirm)),
                (2020, ButtonEvent::LongPress(Button::Confirm)),
                (
                    5020,
                    ButtonEvent::Released {
                        button: Button::Confirm,
                        held_ms: 5000
                    }
                )
            ]
        );
        assert!(!ev[2].1.is_short_press(Button::Confirm));
    }

    #[test]
    fn a_very_long_press_saturates_without_a_second_long_press() {
        let mut b = Debouncer::new();
        let ev = run(&mut b, &[(GREEN, 70_000), (0, 20)]);
        let longs = ev
            .iter()
            .filter(|(_, e)| matches!(e, ButtonEvent::LongPress(_)))
            .count();
        assert_eq!(longs, 1);
        assert_eq!(
            ev.last().unwrap().1,
            ButtonEvent::Released {
                button: Button::Confirm,
                held_ms: u16::MAX
            }
        );
    }

    #[test]
    fn buttons_are_independent() {
        let mut b = Debouncer::new();
        let ev = run(&mut b, &[(GREEN | BASE, 30), (GREEN, 30), (0, 30)]);
        assert_eq!(
            ev,
            [
                (20, ButtonEvent::Pressed(Button::Confirm)),
                (20, ButtonEvent::Pressed(Button::ZeroBase)),
                (
                    50,
                    ButtonEvent::Released {
                        button: Button::ZeroBase,
                        held_ms: 30
                    }
                ),
                (
                    80,
                    ButtonEvent::Released {
                        button: Button::Confirm,
                        held_ms: 60
                    }
                ),
            ]
        );
    }

    proptest! {
        /// Whatever the raw levels, presses and releases alternate per
        /// button, and a press is reported only after 20 ms of pressed level.
        #[test]
        fn presses_and_releases_alternate(runs in proptest::collection::vec((0u8..16, 1u32..60), 1..80)) {
            let mut b = Debouncer::new();
            let mut down = [false; 4];
            let mut longs = [0; 4];
            for (_, e) in run(&mut b, &runs) {
                match e {
                    ButtonEvent::Pressed(k) => {
                        prop_assert!(!down[k as usize]);
                        down[k as usize] = true;
                        longs[k as usize] = 0;
                    }
                    ButtonEvent::Released { button: k, .. } => {
                        prop_assert!(down[k as usize]);
                        down[k as usize] = false;
                    }
                    ButtonEvent::LongPress(k) => {
                        prop_assert!(down[k as usize]);
                        longs[k as usize] += 1;
                        prop_assert_eq!(longs[k as usize], 1);
                    }
                }
            }
            for (k, &down) in down.iter().enumerate() {
                prop_assert_eq!(down, b.pressed() & (1 << k) != 0);
            }
        }
    }
}
