//! What goes to the motor drivers, checked over a whole run of the release
//! image: every HIL test that moves the machine gets this check when its
//! simulation ends ([`check_at_end`], set up by [`crate::machine`] and the
//! tests' own loaders).
//!
//! - A STEP/DIR driver (TB6600 timing, `string-art-machine.md`): no STEP
//!   edge while its ENABLE is in the off state; ENABLE on at least 5 µs
//!   before a DIR change and before a STEP rise; DIR stable 5 µs before a
//!   STEP rise.
//! - A ULN2003 board's inputs (`x_in1`..`z_in4`, where probed): every
//!   change is a half-step of the sequence or a release and a return at
//!   the same phase.

use crate::sim::{Probe, Sim};
use std::cell::Cell;
use taut_logic::axis::{Axis, AXES};
use taut_logic::config::{MachineConfig, TB6600};
use taut_logic::pinmap;

thread_local! {
    /// The ENABLE level that switches each driver on, as the test has set
    /// the firmware up (`$4`, `$<axis>_enable_active_high`).
    static ACTIVE_HIGH: Cell<[bool; AXES]> =
        Cell::new(MachineConfig::STRING_ART.axes.map(|a| a.enable_active_high));
}

/// The test switched the drivers' ENABLE polarity: the end check reads the
/// pins so from now on (per test thread).
pub fn expect_enable_active_high(levels: [bool; AXES]) {
    ACTIVE_HIGH.with(|a| a.set(levels));
}

/// Check [`assert_drivers_timing`] when `sim` ends.
pub fn check_at_end(sim: &mut Sim) {
    sim.check_at_end(assert_drivers_timing);
}

/// Cycles of the TB6600's set-up times (5 µs each).
const ENABLE_SETUP: u64 = TB6600.enable_setup_us as u64 * 16;
const DIR_SETUP: u64 = TB6600.dir_setup_us as u64 * 16;

fn probe_of(sim: &Sim, pin: u8) -> Option<&Probe> {
    sim.probes().iter().find(|p| p.pin() == pin)
}

/// The last edge of `p` to `level` at or before `cycle`.
fn last_edge_to(p: &Probe, level: bool, cycle: u64) -> Option<u64> {
    let edges = p.edges();
    let end = edges.partition_point(|e| e.cycle <= cycle);
    edges[..end]
        .iter()
        .rev()
        .find(|e| e.high == level)
        .map(|e| e.cycle)
}

/// Every rule of the module docs over the whole run; panics with the
/// first broken one.
pub fn assert_drivers_timing(sim: &Sim) {
    let active = ACTIVE_HIGH.with(Cell::get);
    for axis in Axis::ALL {
        let d = pinmap::driver(axis);
        let Some(step) = probe_of(sim, d.step) else {
            continue;
        };
        if step.edge_count() == 0 {
            continue;
        }
        let name = axis.name();
        let en = probe_of(sim, d.enable)
            .unwrap_or_else(|| panic!("{name} steps: probe its ENABLE (D{})", d.enable));
        let on = active[axis.index()];
        let us = |c: u64| c as f64 / 16.0;
        for e in step.edges() {
            assert!(
                en.level_at(e.cycle) == on,
                "{name}: a STEP edge at {:.1} µs while its driver is off",
                us(e.cycle)
            );
            if !e.high {
                continue;
            }
            let since_on = last_edge_to(en, on, e.cycle).map_or(e.cycle, |c| e.cycle - c);
            assert!(
                since_on >= ENABLE_SETUP,
                "{name}: a STEP rise at {:.1} µs, {:.2} µs after ENABLE",
                us(e.cycle),
                us(since_on)
            );
        }
        let Some(dir) = probe_of(sim, d.dir) else {
            continue;
        };
        let rises: Vec<u64> = step
            .edges()
            .iter()
            .filter(|e| e.high)
            .map(|e| e.cycle)
            .collect();
        for e in dir.edges() {
            if en.level_at(e.cycle) == on {
                let since_on = last_edge_to(en, on, e.cycle).map_or(e.cycle, |c| e.cycle - c);
                assert!(
                    since_on >= ENABLE_SETUP,
                    "{name}: DIR changed at {:.1} µs, {:.2} µs after ENABLE",
                    us(e.cycle),
                    us(since_on)
                );
            }
            let next = rises.partition_point(|&r| r <= e.cycle);
            if let Some(&r) = rises.get(next) {
                assert!(
                    r - e.cycle >= DIR_SETUP,
                    "{name}: a STEP rise at {:.1} µs, {:.2} µs after DIR changed",
                    us(r),
                    us(r - e.cycle)
                );
            }
        }
    }
    for axis in 0..AXES {
        let names = taut_simavr::coils::names(axis);
        if names
            .iter()
            .any(|n| !sim.probes().iter().any(|p| p.name() == n))
        {
            continue;
        }
        let track = sim.coil_track(axis);
        assert!(
            track.illegal.is_empty(),
            "{}: coil inputs a 28BYJ-48 cannot follow (at, before, after): {:?}",
            ["x", "y", "z"][axis],
            &track.illegal[..track.illegal.len().min(5)]
        );
    }
}
