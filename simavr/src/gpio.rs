//! Board pins from the outside: probes that record a pin's edges, and inputs
//! driven as a button or a sensor would.

use crate::clock::{cycles_in, cycles_to_ns};
use crate::input;
use crate::probe::{self, Probe, StepDir};
use crate::sim::Sim;
use crate::vcd;
use std::path::Path;
use std::time::Duration;

impl Sim {
    /// Records every edge of board pin `pin` from now on, as signal `name`.
    ///
    /// # Panics
    /// On a pin past D69 or a name already in use.
    pub fn probe(&mut self, pin: u8, name: &str) {
        assert!(
            self.shared().probes.iter().all(|p| p.name() != name),
            "probe name {name} used twice"
        );
        let initial = self.pin_level(pin);
        let index = {
            let probes = &mut self.shared_mut().probes;
            probes.push(Probe::new(name, pin, initial));
            probes.len() - 1
        };
        self.notify_pin(pin, index);
    }

    /// Probes a STEP/DIR pair as `{axis}_step` and `{axis}_dir`; reports give
    /// its net steps.
    pub fn probe_step_dir(&mut self, axis: &str, step: u8, dir: u8, dir_high_is_positive: bool) {
        self.probe(step, &format!("{axis}_step"));
        self.probe(dir, &format!("{axis}_dir"));
        self.step_dir.push(StepDir {
            step,
            dir,
            dir_high_is_positive,
        });
    }

    pub fn probes(&self) -> &[Probe] {
        &self.shared().probes
    }

    /// The probe named `name`.
    ///
    /// # Panics
    /// When no probe has that name.
    pub fn probed(&self, name: &str) -> &Probe {
        let probes = self.probes();
        probes.iter().find(|p| p.name() == name).unwrap_or_else(|| {
            let names: Vec<&str> = probes.iter().map(Probe::name).collect();
            panic!("no probe {name}; probes: {names:?}")
        })
    }

    pub(crate) fn probe_of(&self, pin: u8) -> &Probe {
        self.probe_on(pin)
    }

    fn probe_on(&self, pin: u8) -> &Probe {
        self.probes()
            .iter()
            .find(|p| p.pin() == pin)
            .unwrap_or_else(|| panic!("D{pin} is not probed"))
    }

    /// Net steps of a STEP/DIR pair (both pins probed), see `probe::net_steps`.
    ///
    /// # Panics
    /// When either pin is not probed.
    pub fn net_steps(&self, step_pin: u8, dir_pin: u8, dir_high_is_positive: bool) -> i64 {
        probe::net_steps(
            self.probe_on(step_pin),
            self.probe_on(dir_pin),
            dir_high_is_positive,
        )
    }

    /// Drives an input pin from outside, as a switch or sensor does. The level
    /// holds until changed, even against the MCU's own pull-up.
    pub fn set_input(&mut self, pin: u8, high: bool) {
        self.drive(pin, high);
    }

    /// A button to ground closes: the pin reads low.
    pub fn press(&mut self, pin: u8) {
        self.drive(pin, false);
    }

    /// The button opens: the pull-up brings the pin high.
    pub fn release(&mut self, pin: u8) {
        self.drive(pin, true);
    }

    /// Presses with `bounces` short reopenings, one change every `period`.
    pub fn press_with_bounce(&mut self, pin: u8, bounces: u32, period: Duration) {
        self.bounce(pin, false, bounces, period);
    }

    /// Releases with `bounces` short reclosings, one change every `period`.
    pub fn release_with_bounce(&mut self, pin: u8, bounces: u32, period: Duration) {
        self.bounce(pin, true, bounces, period);
    }

    fn bounce(&mut self, pin: u8, settled: bool, bounces: u32, period: Duration) {
        let plan = input::bounce(self.cycles(), settled, bounces, cycles_in(period));
        for (cycle, high) in plan {
            self.schedule.push(cycle, pin, high);
        }
    }

    /// Writes the probes' edges as a VCD (1 ns timescale), one wire per probe.
    pub fn write_vcd(&self, path: &Path) -> std::io::Result<()> {
        std::fs::write(path, vcd::render(&self.vcd_signals()))
    }

    /// The probes as VCD signals, times in ns.
    pub fn vcd_signals(&self) -> Vec<vcd::Signal> {
        self.probes()
            .iter()
            .map(|p| vcd::Signal {
                name: p.name().to_owned(),
                initial: p.initial(),
                changes: p
                    .edges()
                    .iter()
                    .map(|e| (cycles_to_ns(e.cycle), e.high))
                    .collect(),
            })
            .collect()
    }
}
