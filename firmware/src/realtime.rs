//! Grbl's real-time commands, acted on in the receive path: the receive
//! interrupt takes `?`, `!`, `~` and Ctrl-X out of the byte stream, so
//! they never wait behind a line. Ctrl-X stops the steps there and then;
//! the rest is flagged for the `Realtime` task (the highest software
//! priority), which also writes the status report.
#![deny(unsafe_code)]

use crate::flash_str;
use crate::motion::{Motion, State};
use crate::queues::{REALTIME, RX};
use crate::reply::{self, Fixed, REPORTED_AXES};
use crate::stepper;
use taut_logic::gcode::Realtime;
use taut_logic::kinematics::Kinematics;
use taut_logic::planner::PLANNER_BLOCKS;
use ufmt::uwrite;

const STATUS: u8 = 0;
const HOLD: u8 = 1;
const RESUME: u8 = 2;
const RESET: u8 = 3;

/// Grbl's safety-door byte.
const SAFETY_DOOR: u8 = 0x84;

/// The receive interrupt's part: true when `byte` was a real-time command
/// (flagged: spawn the task), which is then not line input. Grbl 1.1
/// makes every byte from 0x80 up a real-time command: the safety door
/// (0x84) holds as `!` does; jog cancel (0x85), the overrides (0x90–0x9D)
/// and the coolant toggles are taken out of the stream and do nothing
/// here (taut has no jog mode, overrides or coolant), so a sender that
/// sends them never spoils a line.
#[inline(always)]
pub fn on_receive(byte: u8) -> bool {
    let bit = match Realtime::from_byte(byte) {
        None if byte == SAFETY_DOOR => HOLD,
        None if byte >= 0x80 => return true,
        None => return false,
        Some(Realtime::Status) => STATUS,
        Some(Realtime::FeedHold) => HOLD,
        Some(Realtime::CycleStart) => RESUME,
        Some(Realtime::Reset) => {
            stepper::halt();
            RESET
        }
    };
    REALTIME.set(bit);
    true
}

/// The commands taken for one run of the task, in the order they act:
/// reset, hold, resume, status.
#[derive(Clone, Copy)]
pub struct Requests(u16);

impl Requests {
    pub fn take() -> Requests {
        Requests(REALTIME.take())
    }

    fn has(self, bit: u8) -> bool {
        self.0 >> bit & 1 != 0
    }

    pub fn reset(self) -> bool {
        self.has(RESET)
    }

    pub fn hold(self) -> bool {
        self.has(HOLD)
    }

    pub fn resume(self) -> bool {
        self.has(RESUME)
    }

    pub fn status(self) -> bool {
        self.has(STATUS)
    }
}

/// Ask again for a status report that found no room in the TX ring.
pub fn status_later() {
    REALTIME.set(STATUS);
}

/// `<Idle|MPos:0.000,12.500,-3.000|Bf:13,127>`: the state and the
/// position as the pulses left it, in the machine's units, and the free
/// planner blocks and receive bytes (Grbl 1.1's status report);
/// `homing`: the console runs a homing cycle (`Home`).
#[optimize(speed)]
pub fn status(m: &Motion, kin: &impl Kinematics, homing: bool) {
    let mut r = reply::line();
    let state = match m.state() {
        _ if homing => flash_str!("Home"),
        _ if !m.position_known() => flash_str!("Alarm"),
        State::Idle => flash_str!("Idle"),
        State::Run => flash_str!("Run"),
        State::Hold { standing: true } => flash_str!("Hold:0"),
        State::Hold { standing: false } => flash_str!("Hold:1"),
    };
    let _ = uwrite!(r, "<{}{}", state, flash_str!("|MPos:"));
    let pos = kin.forward(&m.stepper.position());
    for (i, p) in pos.iter().take(REPORTED_AXES).enumerate() {
        let _ = uwrite!(r, "{}{}", if i > 0 { "," } else { "" }, Fixed(*p));
    }
    // Grbl 1.1's buffer state (its `$10=1` default): free planner blocks,
    // free bytes of the receive ring (CNCjs sizes its character count by it).
    let planner_free = PLANNER_BLOCKS - m.planned();
    let _ = uwrite!(r, "{}{},{}>", flash_str!("|Bf:"), planner_free, RX.free());
    r.send();
}
