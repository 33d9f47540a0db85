//! Seed 003's raw-step lines on the console (`taut_logic::seed`): read
//! beside G-code, carried out by the executor as a move of the motors by
//! their steps (the planner and the step engine: drivers on, hold and
//! resume, soft limits on its end), answered as the seed answered.
#![deny(unsafe_code)]

use super::{Console, Owner};
use crate::board::port;
use crate::machine_io::Io;
use crate::motion::Motion;
use crate::store::Store;
use taut_logic::config::MachineConfig;
use taut_logic::gcode::{Error, ErrorKind};
use taut_logic::kinematics::Kinematics;
use taut_logic::seed::SeedMove;

/// The seed answered `K` when its serial buffer held this many bytes
/// or more (an Arduino's whole buffer): the host is to wait.
const SEED_FULL: usize = 64;

impl Console {
    /// A seed line: malformed, `?` and nothing moves (the seed's answer),
    /// then `error:1`;
    /// refused as a G-code move would be (a print running from the
    /// serial line, a job, the soft limits, the reach), that error;
    /// else `ok` once queued, as every line here. Then `K` if the input
    /// waiting still fills the seed's buffer.
    #[inline(never)]
    pub(super) fn seed(
        &mut self,
        mv: Option<SeedMove>,
        m: &mut Motion,
        kin: &impl Kinematics,
        cfg: &MachineConfig,
        owner: Owner,
        store: &mut Store,
    ) {
        match mv {
            // The seed's `?`, then Grbl's answer to a line with no
            // command letter: a sender that counts characters gets its
            // line's answer.
            None => {
                if self.source != Some(super::Source::Card) {
                    send(b'?');
                }
                self.error(&Error::new(ErrorKind::ExpectedCommandLetter, 1))
            }
            Some(_) if self.printing_from_serial() => {
                self.error(&Error::new(ErrorKind::Printing, 0))
            }
            Some(mv) => {
                self.jogging = false;
                let owed = self.source != Some(super::Source::Card);
                let env = self.env(kin, cfg, owner);
                let mut io = Io {
                    m,
                    kin,
                    store,
                    replies: owed,
                    trace: None,
                };
                match self.interp.accept_steps(&mv, &env, &mut io) {
                    Ok(()) => self.owed = owed,
                    Err(kind) => self.error(&Error::new(kind, 0)),
                }
            }
        }
        // UART1's 64-byte buffer keeps its last byte for a line's end.
        let port = port::answer();
        if port.rx_len() >= SEED_FULL || port.rx_free() <= 1 {
            send(b'K');
        }
    }
}

/// A one-letter answer line (`?`, `K`), on the line's port: the console
/// waits for room in its TX ring before it takes a line.
fn send(letter: u8) {
    port::answer().send(&[letter, b'\n']);
}
