//! The machine's figures in one typed structure. Defaults are the
//! string-art machine's (`shared/spec/string-art-machine.md`); `machine.txt`
//! on the card and `$` settings override them.

use crate::axis::{PerAxis, AXES};
use crate::units::StepsPerUnit;

/// Per-axis figures. Rates are in steps so the step generator never converts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AxisConfig {
    /// Steps per axis unit (degree for the base, mm for the others).
    pub steps_per_unit: StepsPerUnit,
    /// Highest step rate, steps/s.
    pub max_rate: u32,
    /// Acceleration, steps/s².
    pub accel: u32,
    /// Level of the DIR pin that means the positive direction.
    pub dir_high_is_positive: bool,
    /// Level of the ENABLE pin that switches the driver on.
    pub enable_active_high: bool,
}

/// Pulse timing of the STEP/DIR/ENABLE interface, µs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PulseTiming {
    /// STEP high time.
    pub step_pulse_us: u8,
    /// DIR stable before the STEP rising edge.
    pub dir_setup_us: u8,
    /// ENABLE stable before DIR may change.
    pub enable_setup_us: u8,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MachineConfig {
    pub axes: PerAxis<AxisConfig>,
    pub pulse: PulseTiming,
    /// Grbl's junction deviation, µm: how far the path may cut a corner at
    /// the junction speed. Larger means faster corners.
    pub junction_deviation_um: u32,
}

/// TB6600 defaults: 5 µs pulse, 5 µs DIR set-up, 5 µs ENABLE set-up.
pub const TB6600: PulseTiming = PulseTiming {
    step_pulse_us: 5,
    dir_setup_us: 5,
    enable_setup_us: 5,
};

const fn string_art_axis(steps_per_unit: StepsPerUnit) -> AxisConfig {
    AxisConfig {
        steps_per_unit,
        max_rate: 2000,
        accel: 500,
        dir_high_is_positive: true,
        enable_active_high: true,
    }
}

impl MachineConfig {
    /// The string-art machine: base 200×6×8 = 9600 steps per turn, radial
    /// 200/5 mm × 8 = 32 steps/mm, drill 200/12 mm × 8 = 1600 steps per 12 mm.
    pub const STRING_ART: MachineConfig = MachineConfig {
        axes: [
            string_art_axis(StepsPerUnit::new(9600, 360)),
            string_art_axis(StepsPerUnit::new(32, 1)),
            string_art_axis(StepsPerUnit::new(1600, 12)),
            string_art_axis(StepsPerUnit::new(80, 1)),
        ],
        pulse: TB6600,
        junction_deviation_um: 10,
    };

    pub fn axis(&self, i: usize) -> &AxisConfig {
        &self.axes[i]
    }

    /// Check the figures a user may have overridden; returns the name of the
    /// first bad field.
    pub fn validate(&self) -> Result<(), &'static str> {
        for a in &self.axes[..AXES] {
            if a.steps_per_unit.num == 0 || a.steps_per_unit.den == 0 {
                return Err("steps_per_unit");
            }
            if a.max_rate == 0 || a.max_rate > 200_000 {
                return Err("max_rate");
            }
            if a.accel == 0 {
                return Err("accel");
            }
        }
        if self.pulse.step_pulse_us == 0 {
            return Err("step_pulse_us");
        }
        Ok(())
    }
}

impl Default for MachineConfig {
    fn default() -> Self {
        Self::STRING_ART
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::units::Milli;

    #[test]
    fn defaults_match_the_spec() {
        let c = MachineConfig::default();
        assert_eq!(c.axes[0].steps_per_unit.steps(Milli(360_000)), 9600);
        assert_eq!(c.axes[1].steps_per_unit.steps(Milli(10_000)), 320);
        assert_eq!(c.axes[2].steps_per_unit.steps(Milli(120_000)), 16000);
        assert!(c.validate().is_ok());
    }
}
