//! The simulated machine fitted to the board: its signals probed under
//! their documented names, its coils' half-steps read back, and its MIN
//! end-stops ([`crate::endstop`]) opened and closed as its axes move.

use crate::endstop::Endstop;
use crate::sim::Sim;
use taut_logic::axis::Axis;
use taut_logic::config::MachineConfig;
use taut_logic::machine::Machine;
use taut_logic::pinmap::{self, Button};
use taut_logic::units::Milli;

impl Sim {
    /// Fits a MIN end-stop on board pin `switch`: closed while the axis
    /// driven by the STEP/DIR pair `step`/`dir` (both probed) stands at or
    /// below `at` steps, counted from where it stood when they were probed.
    pub fn endstop(&mut self, switch: u8, step: u8, dir: u8, dir_high_is_positive: bool, at: i64) {
        let e = Endstop::new(switch, step, dir, dir_high_is_positive, at);
        self.drive(switch, !e.closed());
        self.endstops.push(e);
        self.update_endstops();
    }

    /// Whether the end-stop on `switch` has ever closed (the axis was
    /// homed against it, or stood on it).
    pub fn endstop_tripped(&self, switch: u8) -> bool {
        self.endstops
            .iter()
            .any(|e| e.switch() == switch && e.tripped())
    }

    /// Moves every end-stop's axis by the STEP edges since the last look,
    /// and opens or closes its switch.
    pub(crate) fn update_endstops(&mut self) {
        for i in 0..self.endstops.len() {
            let (step, dir) = self.endstops[i].pins();
            let (edges, moved) = self.endstops[i].moved(self.probe_of(step), self.probe_of(dir));
            if edges == 0 {
                continue;
            }
            if let Some(closed) = self.endstops[i].advance(edges, moved) {
                let pin = self.endstops[i].switch();
                self.drive(pin, !closed);
            }
        }
    }
}

/// The MIN switches fitted for a machine's homing axes: per drawing motor,
/// its switch pin and where it closes (steps from power-on).
pub struct MachineEndstops([Option<(u8, i32)>; 2]);

impl Sim {
    /// Probes with the documented signal names: `<channel>_step|dir|en`
    /// (the machine's channel names), `btn_<button>`, `pen_pwm`, `led`.
    pub fn probe_machine(&mut self, machine: Machine) {
        for axis in [Axis::Base, Axis::Radial, Axis::Drill] {
            let d = pinmap::driver(axis);
            let name = machine.channel(axis).to_string();
            self.probe_step_dir(&name, d.step, d.dir, true);
            self.probe(d.enable, &format!("{name}_en"));
        }
        for b in Button::ALL {
            self.probe(b.pin(), &format!("btn_{}", b.name()));
        }
        self.probe(pinmap::PEN_SERVO, "pen_pwm");
        self.probe(pinmap::STATUS_LED, "led");
        self.probe_coils();
    }

    /// Probes every channel's ULN2003 inputs as `x_in1`..`x_in4`,
    /// `y_in*`, `z_in*` ([`crate::coils`] reads them back).
    pub fn probe_coils(&mut self) {
        for (axis, pins) in pinmap::COILS.iter().enumerate() {
            for (pin, name) in pins.iter().zip(crate::coils::names(axis)) {
                self.probe(*pin, &name);
            }
        }
    }

    /// The half-steps of channel `axis`'s coils (0 X, 1 Y, 2 Z), probed
    /// by [`Sim::probe_coils`].
    pub fn coil_track(&self, axis: usize) -> crate::coils::CoilTrack {
        let names = crate::coils::names(axis);
        let probes: [&crate::probe::Probe; 4] = std::array::from_fn(|k| self.probed(&names[k]));
        let edges = probes.map(|p| {
            p.edges()
                .iter()
                .map(|e| (e.cycle, e.high))
                .collect::<Vec<_>>()
        });
        crate::coils::CoilTrack::decode(std::array::from_fn(|k| {
            (probes[k].initial(), edges[k].as_slice())
        }))
    }

    /// The MIN switches of `cfg`'s homing axes, `mm` below where each
    /// stands at power-on (a plotter's X_MIN, Y_MIN, Z_MIN inputs); its
    /// pins probed first.
    pub fn fit_machine_endstops(&mut self, cfg: &MachineConfig, mm: f64) -> MachineEndstops {
        let min_inputs = [Button::ZeroBase, Button::ZeroRadial, Button::ZeroDrill];
        let mut fitted = [None; 2];
        for (i, input) in min_inputs.into_iter().enumerate() {
            if cfg.homing.axes & (1 << i) == 0 {
                continue;
            }
            let d = pinmap::driver(Axis::ALL[i]);
            let at = cfg.axes[i]
                .steps_per_unit
                .steps(Milli((-mm * 1000.0) as i32));
            self.endstop(input.pin(), d.step, d.dir, true, i64::from(at));
            if let Some(f) = fitted.get_mut(i) {
                *f = Some((input.pin(), at));
            }
        }
        MachineEndstops(fitted)
    }
}

impl MachineEndstops {
    /// Where the drawing motors stood at power-on in the machine's own
    /// coordinates: a motor homed against its switch counts from the end
    /// of its travel there (as the firmware does once homed), the others
    /// from zero.
    pub fn power_on_origin(&self, sim: &Sim, cfg: &MachineConfig) -> [i32; 2] {
        let mut origin = [0; 2];
        for (i, f) in self.0.iter().enumerate() {
            if let Some((switch, at)) = *f {
                if sim.endstop_tripped(switch) {
                    let a = &cfg.axes[i];
                    origin[i] = a.steps_per_unit.steps(a.travel.0) - at;
                }
            }
        }
        origin
    }
}
