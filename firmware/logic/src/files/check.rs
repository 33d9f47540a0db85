//! Checking a card's job files in one pass each, in the order the card
//! reader opens them: `param.txt`, then the optional `machine.txt`, then
//! `poradi.txt` (its count and every index checked against the nails).
//! Nothing is kept of `poradi.txt`: winding streams it again. A card
//! without `param.txt` whose `machine.txt` names a plotter is that
//! plotter's card: the machine switches to it ([`Next::Machine`]).
//!
//! The firmware opens [`Files::file`], feeds its bytes to [`Files::push`]
//! and answers its end with [`Files::end`] (or [`Files::missing`] when the
//! card has no such file), until one of them returns [`Next::Done`] or an
//! error. Each file's length and checksum are kept ([`CardId`]): a card put
//! back mid-job is the job's card only if both files are the same.

use crate::config::MachineConfig;
use crate::files::error::{FileError, FileName};
use crate::files::machine::MachineFile;
use crate::files::param::{ParamFile, Params};
use crate::files::poradi::PoradiCheck;
use crate::text::ErrorKind;

/// What the card holds, once every file checked out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Checked {
    pub params: Params,
    /// The machine configuration with `machine.txt`'s overrides.
    pub config: MachineConfig,
    /// Connections in `poradi.txt`.
    pub count: u32,
    pub id: CardId,
}

/// A file's length and a Fletcher-style checksum of its bytes (two
/// wrapping sums: a few cycles a byte on the AVR).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FileSum {
    pub len: u32,
    a: u16,
    b: u16,
}

impl FileSum {
    pub const fn new() -> Self {
        FileSum { len: 0, a: 0, b: 0 }
    }

    pub fn add(&mut self, bytes: &[u8]) {
        for &x in bytes {
            self.a = self.a.wrapping_add(x as u16);
            self.b = self.b.wrapping_add(self.a);
        }
        self.len = self.len.wrapping_add(bytes.len() as u32);
    }

    /// Length and sums, little-endian: kept with a job's checkpoint.
    pub fn to_bytes(self) -> [u8; 8] {
        let l = self.len.to_le_bytes();
        let (a, b) = (self.a.to_le_bytes(), self.b.to_le_bytes());
        [l[0], l[1], l[2], l[3], a[0], a[1], b[0], b[1]]
    }

    pub fn from_bytes(x: [u8; 8]) -> Self {
        FileSum {
            len: u32::from_le_bytes([x[0], x[1], x[2], x[3]]),
            a: u16::from_le_bytes([x[4], x[5]]),
            b: u16::from_le_bytes([x[6], x[7]]),
        }
    }
}

/// The job's files as the card holds them: another card with the same
/// board and count but another pattern is another job.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CardId {
    pub param: FileSum,
    pub poradi: FileSum,
}

/// After a file: open the next one, or all are read. The result stays in
/// the [`Files`] ([`Files::checked`], [`Files::machine`]): on the AVR a
/// copy of it is 187 bytes on the stack under the job's deepest calls.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Next {
    Open(FileName),
    Done,
    /// A plotter's card: `machine.txt` names it, with its settings.
    Machine,
}

enum Stage {
    Param(ParamFile),
    /// No `param.txt`: a plotter's `machine.txt`, or a bad card.
    Plotter(MachineFile),
    Machine(Params, MachineFile),
    Poradi(Params, MachineConfig, PoradiCheck),
    Checked(Checked),
}

pub struct Files {
    stage: Stage,
    id: CardId,
}

impl Default for Files {
    fn default() -> Self {
        Self::new()
    }
}

impl Files {
    pub fn new() -> Self {
        Files {
            stage: Stage::Param(ParamFile::new()),
            id: CardId::default(),
        }
    }

    /// The file being read.
    pub fn file(&self) -> FileName {
        match self.stage {
            Stage::Param(_) => FileName::Param,
            Stage::Plotter(_) | Stage::Machine(..) => FileName::Machine,
            Stage::Poradi(..) | Stage::Checked(_) => FileName::Poradi,
        }
    }

    /// The job's files, once [`Next::Done`].
    pub fn checked(&self) -> Option<&Checked> {
        match &self.stage {
            Stage::Checked(c) => Some(c),
            _ => None,
        }
    }

    /// A plotter card's machine, once [`Next::Machine`] (before, the
    /// lines of `machine.txt` so far).
    pub fn machine(&self) -> Option<&MachineConfig> {
        match &self.stage {
            Stage::Plotter(m) => Some(m.config()),
            _ => None,
        }
    }

    /// Out of line (also `end`, `missing`): inlined into the job task, their
    /// frames would add to its own (the stack peak).
    #[inline(never)]
    pub fn push(&mut self, chunk: &[u8]) -> Result<(), FileError> {
        match &mut self.stage {
            Stage::Param(p) => {
                self.id.param.add(chunk);
                p.push(chunk)
            }
            Stage::Plotter(m) | Stage::Machine(_, m) => m.push(chunk),
            Stage::Poradi(_, _, c) => {
                self.id.poradi.add(chunk);
                c.push(chunk)
            }
            Stage::Checked(_) => Ok(()),
        }
    }

    /// The current file ended. `base`: the configuration in force, which
    /// `machine.txt` amends.
    #[inline(never)]
    pub fn end(&mut self, base: &MachineConfig) -> Result<Next, FileError> {
        // Finished in place: the parsers are too big to move around on the
        // AVR's stack.
        // The next stage is built out of line, off the frame of the checks.
        match &mut self.stage {
            Stage::Param(p) => {
                let params = p.finish()?;
                self.machine_next(params, base);
            }
            Stage::Plotter(m) => {
                let config = m.finish_in_place()?;
                return match config.machine.is_string_art() {
                    true => Err(FileError::whole(FileName::Param, ErrorKind::NotFound)),
                    false => Ok(Next::Machine),
                };
            }
            Stage::Machine(params, m) => {
                let params = *params;
                m.finish_in_place()?;
                self.poradi_next(params);
            }
            Stage::Poradi(_, _, c) => {
                let count = c.finish()?;
                self.checked_next(count);
                return Ok(Next::Done);
            }
            Stage::Checked(_) => return Ok(Next::Done),
        }
        Ok(Next::Open(self.file()))
    }

    /// In place: the stage's figures become the result.
    #[inline(never)]
    fn checked_next(&mut self, count: u32) {
        if let Stage::Poradi(params, config, _) = &self.stage {
            let (params, config, id) = (*params, *config, self.id);
            self.stage = Stage::Checked(Checked {
                params,
                config,
                count,
                id,
            });
        }
    }

    #[inline(never)]
    fn machine_next(&mut self, params: Params, base: &MachineConfig) {
        self.stage = Stage::Machine(params, MachineFile::new(*base));
    }

    /// `poradi.txt` next, with the configuration `machine.txt` made.
    #[inline(never)]
    fn poradi_next(&mut self, params: Params) {
        if let Stage::Machine(_, m) = &mut self.stage {
            let config = *m.config();
            self.stage = Stage::Poradi(params, config, PoradiCheck::new(params.nails));
        }
    }

    /// The card has no such file: only `machine.txt` may be left out, or
    /// `param.txt` on a plotter's card.
    #[inline(never)]
    pub fn missing(&mut self, base: &MachineConfig) -> Result<Next, FileError> {
        // One error built, for either file.
        let file = match self.stage {
            Stage::Param(_) => {
                self.stage = Stage::Plotter(MachineFile::new(*base));
                return Ok(Next::Open(FileName::Machine));
            }
            Stage::Plotter(_) => FileName::Param,
            Stage::Machine(params, _) => {
                self.stage = Stage::Poradi(params, *base, PoradiCheck::new(params.nails));
                return Ok(Next::Open(FileName::Poradi));
            }
            _ => self.file(),
        };
        Err(FileError::whole(file, ErrorKind::NotFound))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::error::tests::show;

    const PARAM: &[u8] = b"tvar = 6\npocet_hrebiku = 24\npolomer_matrice = 20\n";

    /// Reads a card given as (file, contents or None when missing).
    fn read(card: &[(FileName, Option<&[u8]>)]) -> Result<Checked, FileError> {
        let (next, files) = read_any(card)?;
        assert_eq!(next, Next::Done);
        Ok(*files.checked().expect("a job's files"))
    }

    /// Reads a card to its end: a job's files, or a plotter's.
    fn read_any(card: &[(FileName, Option<&[u8]>)]) -> Result<(Next, Files), FileError> {
        let base = MachineConfig::STRING_ART;
        let mut files = Files::new();
        loop {
            let name = files.file();
            let contents = card.iter().find(|(f, _)| *f == name).and_then(|(_, c)| *c);
            let next = match contents {
                None => files.missing(&base)?,
                Some(bytes) => {
                    // Odd chunks, as the card reader's queue delivers them.
                    for chunk in bytes.chunks(7) {
                        files.push(chunk)?;
                    }
                    files.end(&base)?
                }
            };
            if !matches!(next, Next::Open(_)) {
                return Ok((next, files));
            }
        }
    }

    #[test]
    fn a_card_with_only_a_plotters_machine_txt_switches_to_it() {
        let card: &[(FileName, Option<&[u8]>)] = &[(
            FileName::Machine,
            Some(b"machine = flatbed\nx_max_rate = 1500\n"),
        )];
        let (next, files) = read_any(card).unwrap();
        assert_eq!(next, Next::Machine);
        let cfg = files.machine().unwrap();
        assert_eq!(cfg.machine, crate::machine::Machine::Flatbed);
        assert_eq!(cfg.axes[0].max_rate, 1500);
        // Without param.txt, a string-art machine.txt is a bad job card.
        let string_art: &[(FileName, Option<&[u8]>)] =
            &[(FileName::Machine, Some(b"base_max_rate = 1500\n"))];
        assert_eq!(
            show(&read_any(string_art).err().expect("refused")),
            "param.txt: file not found"
        );
    }

    #[test]
    fn a_good_card_without_machine_txt_keeps_the_configuration() {
        let c = read(&[
            (FileName::Param, Some(PARAM)),
            (FileName::Poradi, Some(b"3, 0,12, 23")),
        ])
        .unwrap();
        assert_eq!(
            (c.params.shape, c.params.nails, c.params.radius_um),
            (6, 24, 200_000)
        );
        assert_eq!(c.count, 3);
        assert_eq!(c.config, MachineConfig::STRING_ART);
    }

    #[test]
    fn machine_txt_amends_the_configuration() {
        let c = read(&[
            (FileName::Param, Some(PARAM)),
            (FileName::Machine, Some(b"base_max_rate = 1500\n")),
            (FileName::Poradi, Some(b"1,5")),
        ])
        .unwrap();
        assert_ne!(c.config, MachineConfig::STRING_ART);
    }

    #[test]
    fn the_same_board_and_count_with_another_pattern_is_another_card() {
        let card = |pattern: &'static [u8]| {
            read(&[
                (FileName::Param, Some(PARAM)),
                (FileName::Poradi, Some(pattern)),
            ])
            .unwrap()
        };
        let (a, b) = (card(b"3, 0,12, 23"), card(b"3, 0,13, 22"));
        assert_eq!((a.params, a.count), (b.params, b.count));
        assert_ne!(a.id, b.id);
        assert_eq!(a.id, card(b"3, 0,12, 23").id);
        assert_eq!(a.id.poradi.len, 11);
    }

    #[test]
    fn each_file_reports_its_own_errors() {
        type Card<'a> = &'a [(FileName, Option<&'a [u8]>)];
        let cases: [(Card, &str); 4] = [
            (&[(FileName::Param, None)], "param.txt: file not found"),
            (
                &[(FileName::Param, Some(PARAM)), (FileName::Poradi, None)],
                "poradi.txt: file not found",
            ),
            (
                &[
                    (FileName::Param, Some(PARAM)),
                    (FileName::Poradi, Some(b"2,1,24")),
                ],
                "poradi.txt:1:5: nail 24 out of range (nails: 24)",
            ),
            (
                &[
                    (FileName::Param, Some(PARAM)),
                    (FileName::Machine, Some(b"speed = 3\n")),
                    (FileName::Poradi, Some(b"1,1")),
                ],
                "machine.txt:1:1: unknown key",
            ),
        ];
        for (card, message) in cases {
            assert_eq!(show(&read(card).unwrap_err()), message);
        }
    }
}
