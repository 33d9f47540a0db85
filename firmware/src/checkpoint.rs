//! The job's checkpoint at boot: what the EEPROM held, said in the log with
//! the reset that stopped the job (a power cut shows as `power-on`, a sag
//! as `brown-out` with the BOD fuse set, a stuck task as `watchdog`). The
//! job task logs it once there is room (the boot fills the TX ring).

use crate::board::ResetCause;
use crate::{flash_str, warn};
use taut_logic::checkpoint::{Found, Saved};
use taut_logic::stringart::job::Phase;

#[derive(Clone, Copy)]
pub enum BootNote {
    Corrupt,
    Stopped {
        phase: Phase,
        done: u32,
        total: u32,
        reset: ResetCause,
    },
}

/// The checkpoint to offer, and what to say about it.
pub fn found(found: Found, reset: ResetCause) -> (Option<Saved>, Option<BootNote>) {
    match found {
        // A plotter's print: the console offers it.
        Found::Blank | Found::Idle { .. } | Found::Plot(_) => (None, None),
        Found::Corrupt { .. } => (None, Some(BootNote::Corrupt)),
        Found::Job(s) => {
            let total = match s.phase() {
                Phase::Drilling => s.header.nails as u32,
                Phase::Winding => s.header.count,
            };
            let note = BootNote::Stopped {
                phase: s.phase(),
                done: s.done(),
                total,
                reset,
            };
            (Some(s), Some(note))
        }
    }
}

impl BootNote {
    pub fn log(self) {
        match self {
            BootNote::Corrupt => warn!("checkpoint: corrupt, ignored"),
            BootNote::Stopped {
                phase,
                done,
                total,
                reset,
            } => {
                let what = match phase {
                    Phase::Drilling => flash_str!("drilling"),
                    Phase::Winding => flash_str!("winding"),
                };
                warn!(
                    "checkpoint: ",
                    what,
                    " stopped at ",
                    done,
                    "/",
                    total,
                    " by a reset: ",
                    reset.name()
                );
            }
        }
    }
}
