//! Machine time of a move sequence, for the closing report: every axis runs
//! a trapezoidal profile (rest to rest, its own max rate and acceleration).
//! Host-side: f64, never on the AVR.

use super::MachineStep;
use crate::axis::AXES;
use crate::config::{AxisConfig, MachineConfig};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Overlap {
    /// The axes of a move run at once: the move lasts as long as its
    /// slowest axis (ours).
    Together,
    /// One axis after another, as the original firmware's blocking moves.
    Sequential,
}

/// Seconds for one axis to travel `steps` from rest to rest.
fn trapezoid(steps: u32, axis: &AxisConfig) -> f64 {
    let (d, v, a) = (steps as f64, axis.max_rate as f64, axis.accel as f64);
    if d * a >= v * v {
        // Accelerate to v, cruise, brake: d/v plus v/a for the ramps.
        d / v + v / a
    } else {
        // Never reaches v: accelerate half-way, brake the rest.
        2.0 * libm::sqrt(d / a)
    }
}

/// Seconds the machine takes for `steps`, starting at all-zero positions.
pub fn machine_time(
    steps: impl IntoIterator<Item = MachineStep>,
    config: &MachineConfig,
    overlap: Overlap,
) -> f64 {
    let mut pos = [0i32; AXES];
    let mut total = 0.0;
    for step in steps {
        match step {
            MachineStep::Move(targets) => {
                let mut longest: f64 = 0.0;
                for (i, t) in targets.iter().enumerate() {
                    if let Some(t) = *t {
                        let time = trapezoid(t.abs_diff(pos[i]), &config.axes[i]);
                        match overlap {
                            Overlap::Together => longest = longest.max(time),
                            Overlap::Sequential => total += time,
                        }
                        pos[i] = t;
                    }
                }
                total += longest;
            }
            MachineStep::Dwell(ms) => total += ms as f64 / 1000.0,
            MachineStep::Drivers { .. }
            | MachineStep::Save(_)
            | MachineStep::Mark(_)
            | MachineStep::Durable => {}
        }
    }
    total
}
