//! Grbl's real-time commands, acted on in the receive path: the receive
//! interrupt takes `?`, `!`, `~`, Ctrl-X and the bytes from 0x80 up out
//! of the byte stream, so they never wait behind a line. Ctrl-X stops the
//! steps there and then; the rest is flagged for the `Realtime` task (the
//! highest software priority), which also writes the status report
//! (formatted by `taut_logic::gcode::Status`).

use crate::board::port::Port;
use crate::console::{Activity, Frame};
use crate::endstop;
use crate::log::Line;
use crate::motion::{self, Motion};
use crate::reply;
use crate::rt::{Flags, Tally, TaskCell};
use crate::stepper;
use crate::{flash_str, info, warn};
use taut_logic::config::MachineConfig;
use taut_logic::gcode::{Overrides, Realtime, Refresh, State, Status, OVERRIDE_BYTES};
use taut_logic::interp::motor_channels;
use taut_logic::kinematics::Kinematics;
use taut_logic::settings::grbl::{report_angles, report_axes};
use ufmt::uwrite;

const STATUS: u8 = 0;
const HOLD: u8 = 1;
const RESUME: u8 = 2;
const RESET: u8 = 3;
const DOOR: u8 = 4;
const JOG_CANCEL: u8 = 5;
/// The override bytes 0x90–0x97, a bit each from here.
const OVERRIDES: u8 = 6;
/// `?` from UART1: its report goes there.
const STATUS_UART1: u8 = OVERRIDES + 8;

/// Receive interrupts → `Realtime` task: `?`, `!`, `~`, Ctrl-X, the
/// override bytes. Private: set only by [`on_receive`] (and
/// [`status_later`]), taken only by [`Requests::take`].
static REALTIME: Flags = Flags::new();
/// Receive interrupts → `Realtime` task: the feed override's ±10 % and
/// ±1 % presses since the last run, summed (each one counts).
static FEED_PRESSES: Tally = Tally::new();

/// Grbl's safety-door and jog-cancel bytes.
const SAFETY_DOOR_BYTE: u8 = 0x84;
const JOG_CANCEL_BYTE: u8 = 0x85;

/// The receive interrupt's part: true when `byte` was a real-time command
/// (flagged: spawn the task), which is then not line input. Grbl 1.1
/// makes every byte from 0x80 up a real-time command: the safety door
/// (0x84), jog cancel (0x85) and the feed and rapid overrides (0x90–0x97)
/// are flagged; the spindle overrides and coolant toggles are taken out
/// of the stream and do nothing (taut has no spindle or coolant), so a
/// sender that sends them never spoils a line.
#[inline(always)]
pub fn on_receive(byte: u8) -> bool {
    let bit = match Realtime::from_byte(byte) {
        Some(Realtime::Status) => STATUS,
        Some(Realtime::FeedHold) => HOLD,
        Some(Realtime::CycleStart) => RESUME,
        Some(Realtime::Reset) => {
            stepper::halt();
            RESET
        }
        None => match byte {
            SAFETY_DOOR_BYTE => DOOR,
            JOG_CANCEL_BYTE => JOG_CANCEL,
            0x90..=0x97 => {
                // 0x90 (100 %) cancels the presses before it; 0x91-0x94
                // each add theirs, however many come before the task runs.
                match byte {
                    0x90 => FEED_PRESSES.clear(),
                    0x91 => FEED_PRESSES.add(10),
                    0x92 => FEED_PRESSES.add(-10),
                    0x93 => FEED_PRESSES.add(1),
                    0x94 => FEED_PRESSES.add(-1),
                    _ => {}
                }
                OVERRIDES + (byte - OVERRIDE_BYTES)
            }
            0x80.. => return true,
            _ => return false,
        },
    };
    REALTIME.set(bit);
    true
}

/// The receive interrupt's part for UART1: as [`on_receive`], its `?`
/// flagged apart (the report is written to the port that asked).
#[inline(always)]
pub fn on_receive_uart1(byte: u8) -> bool {
    if Realtime::from_byte(byte) == Some(Realtime::Status) {
        REALTIME.set(STATUS_UART1);
        return true;
    }
    on_receive(byte)
}

/// The commands taken for one run of the task, in the order they act:
/// reset, jog cancel, hold, resume, overrides, status.
#[derive(Clone, Copy)]
pub struct Requests(u16, i16);

impl Requests {
    pub fn take() -> Requests {
        // Masked each: a press between the two takes runs the task again.
        Requests(REALTIME.take(), FEED_PRESSES.take())
    }

    fn has(self, bit: u8) -> bool {
        self.0 >> bit & 1 != 0
    }

    pub fn reset(self) -> bool {
        self.has(RESET)
    }

    pub fn jog_cancel(self) -> bool {
        self.has(JOG_CANCEL)
    }

    /// `!` or the safety door.
    pub fn hold(self) -> bool {
        self.has(HOLD) || self.door()
    }

    pub fn door(self) -> bool {
        self.has(DOOR)
    }

    pub fn resume(self) -> bool {
        self.has(RESUME)
    }

    /// The override bytes that came: bit `i` for 0x90 + `i`.
    pub fn overrides(self) -> u8 {
        (self.0 >> OVERRIDES) as u8
    }

    /// The feed override's presses summed, percent (after a 0x90 if one
    /// came).
    pub fn feed_presses(self) -> i16 {
        self.1
    }

    /// `?` from `port`.
    pub fn status(self, port: Port) -> bool {
        self.has(match port {
            Port::Usb => STATUS,
            Port::Uart1 => STATUS_UART1,
        })
    }
}

/// Ask again for a status report that found no room in `port`'s TX ring.
pub fn status_later(port: Port) {
    REALTIME.set(match port {
        Port::Usb => STATUS,
        Port::Uart1 => STATUS_UART1,
    });
}

/// Ctrl-X done: in Grbl's words, alarm 6 (reset while homing) or 3 (while
/// moving: steps may be lost), the greeting, and while motion is locked
/// how to unlock it.
#[inline(never)]
pub fn after_reset(m: &mut Motion, homing: bool, moving: bool) {
    if homing {
        m.lose_position();
        reply::alarm(6);
    } else if moving {
        reply::alarm(3);
    }
    reply::banner();
    match m.position_known() {
        true => info!("reset"),
        false => {
            Port::each(|port| {
                let mut r = Line::to(port);
                let _ = uwrite!(r, "{}", flash_str!("[MSG:'$H'|'$X' to unlock]"));
                r.send();
            });
            warn!("position unknown until $H, $X or zeroing");
        }
    }
}

/// What the real-time commands leave behind them.
pub struct Standing {
    pub overrides: Overrides,
    refresh: Refresh,
    /// The hold came from the safety door.
    pub door: bool,
}

/// The `Realtime` task's.
pub static STANDING: TaskCell<Standing> = TaskCell::new(Standing::new());

impl Standing {
    const fn new() -> Standing {
        Standing {
            overrides: Overrides::NONE,
            refresh: Refresh::new(),
            door: false,
        }
    }

    /// Ctrl-X: Grbl's defaults again.
    pub fn reset(&mut self) {
        *self = Standing::new();
    }

    /// Override bytes (bit `i`: 0x90 + `i`) with the feed's presses
    /// counted apart (`feed`, percent); true if the overrides changed (the
    /// next report carries them).
    pub fn apply(&mut self, bits: u8, feed: i16) -> bool {
        let changed = self.overrides.apply_counted(bits, feed);
        if changed {
            self.refresh.overrides_changed();
        }
        changed
    }
}

/// Grbl 1.1's status report: `<Run|MPos:0.000,12.500,-3.000|Bf:12,100|FS:600,0>`,
/// the position as the pulses left it in the report's X, Y, Z places
/// (a plotter's pen channel as programmed: no motor counts its `Z`),
/// the machine's or the work's as `$10` says, in `$13`'s unit, and the
/// work offset every so often and after it changed. Out of line: the
/// task's frame stays small when no report is asked for. To `port`,
/// `Bf:` its receive ring's room.
#[inline(never)]
pub fn status(
    port: Port,
    m: &Motion,
    kin: &impl Kinematics,
    cfg: &MachineConfig,
    activity: Activity,
    frame: &Frame,
    rt: &mut Standing,
) {
    let state = match (activity, m.state()) {
        (Activity::Sleeping, _) => State::Sleep,
        (Activity::Homing, _) => State::Home,
        _ if !m.position_known() => State::Alarm,
        (Activity::Checking, _) => State::Check,
        (_, motion::State::Hold { standing }) if rt.door => State::Door { standing },
        (_, motion::State::Hold { standing }) => State::Hold { standing },
        (Activity::Jogging, motion::State::Run) => State::Jog,
        (_, motion::State::Run) => State::Run,
        (_, motion::State::Idle) => State::Idle,
    };
    let busy = !matches!(
        state,
        State::Idle | State::Alarm | State::Check | State::Sleep
    );
    let places = report_axes(cfg.machine);
    let mut at = kin.forward(&m.stepper.position());
    let motors = motor_channels(cfg);
    for (i, a) in at.iter_mut().enumerate() {
        if motors >> i & 1 == 0 {
            *a = frame.programmed[i];
        }
    }
    if frame.changed {
        rt.refresh.wco_changed();
    }
    // A plotter's MIN inputs are its limit switches (the string-art
    // machine's are buttons).
    let mut pins = 0;
    if !cfg.machine.is_string_art() {
        for (p, axis) in places.iter().enumerate() {
            pins |= (endstop::closed(axis.index()) as u8) << p;
        }
    }
    let report = Status {
        state,
        position: places.map(|a| at[a.index()]),
        wco: places.map(|a| frame.wco[a.index()]),
        angles: report_angles(cfg.machine),
        feed: m.feed(),
        buffer: (m.free_blocks() as u8, port.rx_free() as u8),
        pins,
        overrides: rt.overrides,
        extra: rt.refresh.next(busy),
        fields: cfg.status_report,
        inches: cfg.report_inches,
    };
    let mut r = Line::to(port);
    let _ = uwrite!(r, "{}", report);
    r.send();
}
