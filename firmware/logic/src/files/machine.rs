//! `machine.txt` (optional): overrides of the machine settings, one
//! `key = value` a line with the names of [`crate::settings`]:
//!
//! ```text
//! drill_steps_per_unit = 1600/12   # 200 steps × 8 per 12 mm
//! base_max_rate = 1500
//! ```
//! The overrides apply to a copy of the configuration, returned only if
//! the whole file is good: a bad file changes nothing.

use crate::config::MachineConfig;
use crate::files::error::{FileError, FileName};
use crate::files::kv::{Item, KvReader};
use crate::settings::{GlobalField, Setting, SettingError, COUNT};
use crate::text::ErrorKind;

const FILE: FileName = FileName::Machine;

/// Streaming parser of `machine.txt`: `push` chunks, then `finish`.
pub struct MachineFile {
    kv: KvReader,
    cfg: MachineConfig,
    /// Settings already given, a bit each by [`Setting::index`]: bytes,
    /// as a `u64`'s shifts and tests are long on the AVR.
    seen: [u8; SEEN],
}

const SEEN: usize = COUNT.div_ceil(8);

impl MachineFile {
    /// Starts from `base`, the configuration in force.
    pub const fn new(base: MachineConfig) -> Self {
        MachineFile {
            kv: KvReader::new(FILE),
            cfg: base,
            seen: [0; SEEN],
        }
    }

    pub fn push(&mut self, chunk: &[u8]) -> Result<(), FileError> {
        let (cfg, seen) = (&mut self.cfg, &mut self.seen);
        self.kv
            .push_chunk(chunk, &mut |item| apply(cfg, seen, item))
    }

    /// The configuration with the file's overrides, checked as a whole.
    pub fn finish(&mut self) -> Result<MachineConfig, FileError> {
        self.finish_in_place().copied()
    }

    /// The configuration as the lines so far made it.
    pub fn config(&self) -> &MachineConfig {
        &self.cfg
    }

    /// [`MachineFile::finish`] leaving the configuration where it is: no
    /// copy on the (AVR's small) stack.
    pub fn finish_in_place(&mut self) -> Result<&MachineConfig, FileError> {
        if let Some(item) = self.kv.finish()? {
            apply(&mut self.cfg, &mut self.seen, item)?;
        }
        self.cfg
            .validate()
            .map_err(|kind| FileError::whole(FILE, kind))?;
        Ok(&self.cfg)
    }
}

fn apply(cfg: &mut MachineConfig, seen: &mut [u8; SEEN], item: Item<'_>) -> Result<(), FileError> {
    let at_key = |kind| FileError::at(FILE, item.line, item.key_col, kind);
    let Some(setting) = Setting::parse(item.key, cfg.machine) else {
        return Err(at_key(ErrorKind::UnknownKey));
    };
    let (byte, bit) = (setting.index() / 8, 1 << (setting.index() % 8));
    if seen[byte] & bit != 0 {
        return Err(at_key(ErrorKind::DuplicateKey));
    }
    // The machine loads its defaults whole: it would undo the lines above.
    if setting == Setting::Global(GlobalField::Machine) && seen.iter().any(|&b| b != 0) {
        return Err(at_key(ErrorKind::Invalid(taut_progmem::text!(
            "machine: the first key"
        ))));
    }
    seen[byte] |= bit;
    // Values are trimmed ASCII up to any error, so bytes are columns.
    setting.set(cfg, item.value).map_err(|e: SettingError| {
        FileError::at(FILE, item.line, item.value_col + e.at as u32, e.kind)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::files::error::tests::in_every_chunking;
    use crate::text::error::tests::show;
    use crate::units::StepsPerUnit;
    use proptest::prelude::*;
    use std::string::String;

    fn parse_in_chunks(text: &[u8], chunk: usize) -> Result<MachineConfig, FileError> {
        let mut m = MachineFile::new(MachineConfig::STRING_ART);
        for part in text.chunks(chunk) {
            m.push(part)?;
        }
        m.finish()
    }

    fn parse(text: &str) -> Result<MachineConfig, String> {
        in_every_chunking(text, parse_in_chunks)
    }

    #[test]
    fn overrides_apply_to_their_fields_only() {
        let cfg = parse(
            "\u{FEFF}# our drill has a finer screw\r\n\
             drill_steps_per_unit = 1600/10\r\n\
             Base_Max_Rate=1500\r\n\
             \r\n\
             step_pulse_us = 10  # slower drivers\r\n",
        )
        .unwrap();
        let mut expected = MachineConfig::STRING_ART;
        expected.axes[2].steps_per_unit = StepsPerUnit::new(1600, 10);
        expected.axes[0].max_rate = 1500;
        expected.pulse.step_pulse_us = 10;
        assert_eq!(cfg, expected);
        assert_eq!(
            parse(""),
            Ok(MachineConfig::STRING_ART),
            "an empty file overrides nothing"
        );
    }

    #[test]
    fn bad_files_say_where_and_what() {
        let bad: &[(&str, &str)] = &[
            ("base_speed = 5\n", "machine.txt:1:1: unknown key"),
            ("accel = 5\n", "machine.txt:1:1: unknown key"),
            (
                "base_accel = 5\n  BASE_ACCEL = 6\n",
                "machine.txt:2:3: duplicate key",
            ),
            (
                "radial_max_rate = 0\n",
                "machine.txt:1:19: expected 1 to 200000",
            ),
            (
                "radial_max_rate = 300000\n",
                "machine.txt:1:19: expected 1 to 200000",
            ),
            (
                "radial_max_rate = 2e3\n",
                "machine.txt:1:20: expected a number",
            ),
            (
                "drill_dir_invert = yes\n",
                "machine.txt:1:20: expected a number",
            ),
            (
                "drill_steps_per_unit = 1600/x\n",
                "machine.txt:1:29: expected a number",
            ),
            (
                "drill_steps_per_unit = 0/12\n",
                "machine.txt:1:24: invalid steps_per_unit",
            ),
            (
                "junction_deviation_um = 99999999999\n",
                "machine.txt:1:25: number too big",
            ),
            ("step_pulse_us\n", "machine.txt:1:1: expected key = value"),
        ];
        for (text, message) in bad {
            assert_eq!(parse(text), Err(String::from(*message)), "{text:?}");
        }
    }

    proptest! {
        #[test]
        fn listed_settings_read_back_as_a_file(
            rates in proptest::collection::vec(1u32..=100_000, 4),
            num in 1u32..100_000,
            den in 1u32..100,
            chunk in 1usize..70,
        ) {
            let mut cfg = MachineConfig::STRING_ART;
            for (axis, rate) in cfg.axes.iter_mut().zip(&rates) {
                axis.max_rate = *rate;
                axis.steps_per_unit = StepsPerUnit::new(num, den);
            }
            let mut text = String::new();
            crate::settings::for_each(&cfg, |s, v| text += &(show(&crate::settings::Named(s, cfg.machine)) + " = " + &show(&v) + "\n"));
            prop_assert_eq!(parse_in_chunks(text.as_bytes(), chunk), Ok(cfg));
        }
    }
}
