//! Host tests of the executor against a recording machine: Grbl's
//! step-3 errors in `gcode.c`'s order, work coordinates and offsets,
//! soft limits in machine coordinates, the exact programmed position,
//! the pen from spindle and `Z` words, program end, `$G`.

use super::*;
use crate::coords::CoordData;
use crate::gcode::{Input, Parser};
use crate::kinematics::AnyKinematics;
use crate::machine::Machine;
use proptest::prelude::*;
use std::{format, string::String, string::ToString, vec::Vec};

/// What the executor asked of the machine, in order.
#[derive(Clone, Debug, PartialEq)]
enum Did {
    Move(Steps, Feed),
    /// A piece of a path on the whiteboard or the arm.
    Piece(Piece, Feed),
    Pen(u8),
    Drivers(bool),
    IdleDelay(u32),
    Pause,
    Report,
    End,
}

/// A machine that does at once what it is asked and writes it down.
struct Recorder {
    did: Vec<Did>,
    coords: CoordData,
    clock: u32,
    pen: Option<u8>,
    /// Pieces to refuse before the next is taken (a full planner).
    refuse: u32,
}

impl MachineIo for Recorder {
    fn coord(&self, index: u8) -> Exact {
        coords::stored(&self.coords, index)
    }
    fn set_coord(&mut self, index: u8, value: &Exact) {
        coords::store(&mut self.coords, index, value)
    }
    fn room(&mut self, _piece: bool) -> Option<Wait> {
        None
    }
    fn steps(&self) -> Steps {
        let last = self.did.iter().rev().find_map(|d| match d {
            Did::Move(s, _) => Some(*s),
            Did::Piece(p, _) => Some(p.steps),
            _ => None,
        });
        last.unwrap_or_default()
    }
    fn queue(&mut self, steps: &Steps, feed: Feed) -> bool {
        self.did.push(Did::Move(*steps, feed));
        true
    }
    fn queue_piece(&mut self, piece: &Piece, feed: Feed) -> bool {
        if self.refuse > 0 {
            self.refuse -= 1;
            return false;
        }
        self.did.push(Did::Piece(*piece, feed));
        true
    }
    fn idle(&mut self) -> bool {
        true
    }
    fn pen(&mut self, deg: u8) -> bool {
        self.did.push(Did::Pen(deg));
        self.pen.replace(deg) != Some(deg)
    }
    fn drivers(&mut self, on: bool) {
        self.did.push(Did::Drivers(on))
    }
    fn idle_delay(&mut self, ms: u32) {
        self.did.push(Did::IdleDelay(ms))
    }
    fn pause(&mut self) {
        self.did.push(Did::Pause)
    }
    fn report_position(&mut self) {
        self.did.push(Did::Report)
    }
    fn program_end(&mut self) {
        self.did.push(Did::End)
    }
    fn millis(&self) -> u32 {
        self.clock
    }
}

/// The executor's view in check mode (`$C`).
fn checking<'a>(kin: &'a AnyKinematics, cfg: &'a MachineConfig) -> Env<'a, AnyKinematics> {
    Env {
        kin,
        cfg,
        allowed: Allowed {
            motion: true,
            checking: true,
        },
    }
}

/// A machine with its executor.
struct Bench {
    interp: Interpreter,
    kin: AnyKinematics,
    cfg: MachineConfig,
    io: Recorder,
}

impl Bench {
    fn new(machine: Machine) -> Bench {
        let cfg = MachineConfig::defaults(machine);
        let io = Recorder {
            did: Vec::new(),
            coords: CoordData::ZERO,
            clock: 0,
            pen: None,
            refuse: 0,
        };
        let mut interp = Interpreter::new();
        interp.reset(&io.coord(0));
        Bench {
            interp,
            kin: AnyKinematics::of(&cfg).unwrap(),
            cfg,
            io,
        }
    }

    /// A flatbed standing at `x`, `y` (machine mm).
    fn flatbed_at(x: i32, y: i32) -> Bench {
        let mut b = Bench::new(Machine::Flatbed);
        b.interp
            .resync(&[Milli(x * 1000), Milli(y * 1000), Milli(0)], 0b111);
        b
    }

    /// Sends `text` (one line) and carries it out whole, then the input
    /// pauses (tiny moves joined are queued); Grbl's error code if refused.
    fn send(&mut self, text: &str) -> Result<(), u8> {
        self.stream(text)?;
        self.interp.flush_soon();
        self.run_out();
        Ok(())
    }

    /// [`Bench::send`] with more lines coming: tiny moves stay joined.
    fn stream(&mut self, text: &str) -> Result<(), u8> {
        self.take(text)?;
        self.run_out();
        Ok(())
    }

    /// `text` accepted, not yet carried out.
    fn take(&mut self, text: &str) -> Result<(), u8> {
        let mut p = Parser::new();
        let mut out: Vec<_> = text
            .bytes()
            .chain([b'\n'])
            .filter_map(|b| p.push(b))
            .collect();
        assert_eq!(out.len(), 1, "{text:?}");
        let env = Env {
            kin: &self.kin,
            cfg: &self.cfg,
            allowed: Allowed::ALL,
        };
        let (interp, io) = (&mut self.interp, &mut self.io);
        match out.remove(0) {
            Ok(Input::Block(b)) => interp.accept(&b, false, &env, io),
            Ok(Input::Jog(b)) => interp.accept(&b, true, &env, io),
            Ok(Input::Seed(Some(mv))) => interp.accept_steps(&mv, &env, io),
            Ok(other) => panic!("{text:?}: {other:?}"),
            Err(e) => return Err(e.code()),
        }
        .map_err(|e| e as u8)?;
        Ok(())
    }

    /// The accepted line carried out.
    fn run_out(&mut self) {
        let env = Env {
            kin: &self.kin,
            cfg: &self.cfg,
            allowed: Allowed::ALL,
        };
        loop {
            match self.interp.run(&env, &mut self.io) {
                Progress::Done => return,
                Progress::Wait(Wait::Ms(ms)) => self.io.clock += ms as u32,
                Progress::Wait(_) => {}
            }
        }
    }

    #[track_caller]
    fn ok(&mut self, text: &str) {
        if let Err(code) = self.send(text) {
            panic!("{text:?}: error:{code}");
        }
    }

    fn err(&mut self, text: &str) -> u8 {
        self.send(text).err().unwrap_or(0)
    }

    /// The last move's steps.
    fn steps(&self) -> Steps {
        self.io
            .did
            .iter()
            .rev()
            .find_map(|d| match d {
                Did::Move(s, _) => Some(*s),
                Did::Piece(p, _) => Some(p.steps),
                _ => None,
            })
            .expect("no move")
    }

    /// The pieces queued, in order.
    fn pieces(&self) -> Vec<(Piece, Feed)> {
        self.io
            .did
            .iter()
            .filter_map(|d| match d {
                Did::Piece(p, f) => Some((*p, *f)),
                _ => None,
            })
            .collect()
    }

    fn moves(&self) -> usize {
        self.io
            .did
            .iter()
            .filter(|d| matches!(d, Did::Move(..)))
            .count()
    }

    /// `$G` as the console prints it.
    fn gc(&self) -> String {
        show(&self.interp.parser_state(false))
    }

    /// Machine position, mm (µm rounded).
    fn mpos(&self) -> [i32; 3] {
        self.interp.target().map(|m| m.0)
    }

    fn wco(&self) -> [i32; 3] {
        self.interp.wco().map(|m| m.0)
    }
}

fn show(d: &impl ufmt::uDisplay) -> String {
    crate::text::error::tests::show(d)
}

/// (setup lines, line, Grbl's error, gcode.c line): step 3's checks on
/// the flatbed (words X Y and the pen's Z), in Grbl's order.
const STEP_3: &[(&str, &str, u8, &str)] = &[
    ("", "G1 X1", 22, "665: no feed rate yet"),
    ("", "G2 X1 I1", 22, "665"),
    ("G93", "G1 X1", 22, "401: G93 needs F on every feed move"),
    ("G93 G1 X1 F10", "X2", 22, "401"),
    (
        "G1 F100 G93",
        "G94 G1 X1",
        22,
        "423: from G93 no feed is kept",
    ),
    ("", "G4", 28, "456: dwell without P"),
    ("", "G10 L20 X0", 28, "not reached: L without P is fine"),
    ("", "G10 X0", 28, "533: neither L nor P"),
    ("", "G10 L20 P1", 26, "532: no axis words"),
    ("", "G10 L2 P7 X0", 29, "535: P above 6"),
    ("", "G10 L3 P1 X0", 20, "539: L other than 2 or 20"),
    ("", "G10 L2 P1 R1 X0", 20, "538: G10 L2 with R"),
    ("", "G92", 26, "563"),
    ("", "G53 G2 X1 I1 F100", 30, "630: G53 only with G0 or G1"),
    ("G80", "X1", 31, "640: axis words in G80"),
    ("", "G80 G28 X1", 31, "640: even non-modal commands"),
    ("", "G4 P1 X1", 31, "never: bare axis words move in G0"),
    ("", "G2 F100", 26, "678: an explicit G2 needs axis words"),
    (
        "G1 F100",
        "G1",
        0,
        "not an error: G1 alone changes the mode",
    ),
    ("", "G2 X1 F100", 35, "846: no offset in the plane"),
    ("", "G2 Z1 I1 F100", 32, "688: no axis word of the plane"),
    (
        "",
        "G2 X70 Y0 R5 F100",
        33,
        "694: R with the end at the start",
    ),
    ("", "G2 X20 R5 F100", 34, "769: radius too small"),
    (
        "",
        "G2 X10 I3 F100",
        33,
        "826: end off the circle by over 0.5 mm",
    ),
    ("", "G1 X1 I1 F100", 36, "859: I without an arc"),
    ("", "G1 X1 P1 F100", 36, "859: P without G4 or G10"),
    ("", "G0 X1 L2", 36, "859"),
    (
        "",
        "G2 X72 I1 R1 F100",
        36,
        "859: I left over in radius form",
    ),
    ("", "G43.1 X1", 37, "491: G43.1 takes Z only"),
    ("", "G43.1 Z1 X1", 37, "491"),
    ("", "$J=X1", 22, "396: a jog needs F"),
    (
        "",
        "$J=G1 X1 F100",
        16,
        "856: a jog takes no motion command",
    ),
    ("", "$J=G17 X1 F100", 16, "856"),
    ("", "$J=G28 X1 F100", 16, "857"),
    ("", "$J=X1 S1 F100", 36, "859: S unused in a jog"),
    ("", "$J=F100", 26, "jogging.md: an axis word is required"),
    ("", "G0 X141", 15, "taut: out of the 0…140 mm travel"),
    ("", "G1 X1 F5", 72, "taut: a feed below 10 mm/min"),
];

#[test]
fn grbl_s_step_3_errors_in_gcode_c_s_order() {
    for (setup, line, code, why) in STEP_3 {
        let mut b = Bench::flatbed_at(70, 0);
        for l in setup.split('\n').filter(|l| !l.is_empty()) {
            b.ok(l);
        }
        let got = b.send(line).err();
        let expected = match why.starts_with("not") || why.starts_with("never") {
            true => None,
            false => Some(*code),
        };
        assert_eq!(got, expected, "{setup:?} then {line:?} (gcode.c {why})");
    }
}

#[test]
fn a_refused_line_changes_nothing() {
    let mut b = Bench::flatbed_at(70, 0);
    let gc = b.gc();
    assert_eq!(b.err("G91 G21 G55 G1 X1"), 22);
    assert_eq!(b.gc(), gc);
    assert_eq!(b.err("G92 X0 G4"), 21);
    assert_eq!(b.err("G10 L2 P9 X1"), 29);
    assert_eq!(b.wco(), [0; 3]);
    assert_eq!(b.moves(), 0);
}

/// The sender's "zero" button: homed, at the middle of the bed, `G10 L20
/// P1 X0 Y0` makes it the work zero; `G0 X0 Y0` goes back to it; the
/// machine position never changes by an offset.
#[test]
fn work_zero_with_g10_l20_and_moves_in_work_coordinates() {
    let mut b = Bench::flatbed_at(70, 100);
    b.ok("G10 L20 P1 X0 Y0");
    assert_eq!(b.wco(), [70_000, 100_000, 0]);
    assert_eq!(b.mpos(), [70_000, 100_000, 0]);
    assert_eq!(
        coords::stored(&b.io.coords, 0),
        [70_000_000, 100_000_000, 0]
    );
    b.ok("G0 X-20 Y5");
    assert_eq!(b.mpos(), [50_000, 105_000, 0]);
    assert_eq!(b.steps(), [2000, 4200, 0]);
    // G53: machine coordinates for one line.
    b.ok("G53 G0 X10");
    assert_eq!(b.mpos(), [10_000, 105_000, 0]);
    b.ok("G0 X0 Y0");
    assert_eq!(b.mpos(), [70_000, 100_000, 0]);
    // G55 has no offset: its zero is the machine's.
    b.ok("G55 G0 X0");
    assert_eq!(b.mpos(), [0, 100_000, 0]);
    assert_eq!(b.gc(), "G0 G55 G17 G21 G90 G94 M5 M9 T0 F0 S0");
    b.ok("G10 L2 P2 X5");
    assert_eq!(b.wco(), [5_000, 0, 0]);
    b.ok("G10 L2 P0 Y7");
    assert_eq!(coords::stored(&b.io.coords, 1), [5_000_000, 7_000_000, 0]);
    b.ok("G54");
    assert_eq!(b.wco(), [70_000, 100_000, 0]);
}

/// `G92` is an offset, never a new machine position: the travel stays
/// where the machine has it (the safety hole this closes: at X20, `G92
/// X0` then `G0 X139` went 19 mm past the 140 mm travel).
#[test]
fn g92_is_an_offset_and_the_travel_stays_in_machine_coordinates() {
    let mut b = Bench::flatbed_at(20, 0);
    b.ok("G92 X0");
    assert_eq!(b.wco(), [20_000, 0, 0]);
    assert_eq!(b.mpos(), [20_000, 0, 0]);
    assert_eq!(b.err("G0 X139"), 15);
    assert_eq!(b.err("G0 X-21"), 15);
    b.ok("G0 X120");
    assert_eq!(b.mpos(), [140_000, 0, 0]);
    b.ok("G0 X-20");
    assert_eq!(b.steps()[0], 0);
    // G10 L20 counts the G92 offset (WCS = MPos − G92 − WPos).
    b.ok("G10 L20 P1 X5");
    assert_eq!(coords::stored(&b.io.coords, 0)[0], -25_000_000);
    assert_eq!(b.wco(), [-5_000, 0, 0]);
    b.ok("G92.1");
    assert_eq!(b.wco(), [-25_000, 0, 0]);
    // A jog is refused past the travel too (Grbl's error 15).
    assert_eq!(b.err("$J=G53 X150 F1000"), 15);
    b.ok("$J=G91 X10 F1000");
    assert_eq!(b.mpos()[0], 10_000);
}

#[test]
fn g28_and_g30_go_to_their_stored_positions() {
    let mut b = Bench::flatbed_at(30, 40);
    b.ok("G28.1");
    b.ok("G0 X50 Y60");
    b.ok("G30.1");
    b.ok("G0 X10 Y10");
    b.ok("G28");
    assert_eq!(b.mpos(), [30_000, 40_000, 0]);
    assert_eq!(b.moves(), 3);
    // Through a point, then only the named axis goes home.
    b.ok("G30 X20");
    assert_eq!(b.mpos(), [50_000, 40_000, 0]);
    let n = b.io.did.len();
    assert_eq!(b.io.did[n - 2], Did::Move([800, 1600, 0], Feed::Rapid));
    assert_eq!(b.io.did[n - 1], Did::Move([2000, 1600, 0], Feed::Rapid));
}

/// Grbl keeps the programmed position unrounded and rounds the absolute
/// target to steps once: 2 000 × `G91 G1 X0.0125` is 25 mm exactly, 2 000
/// × `X0.00049` inch is 24.892 mm (996 steps of 0.025 mm).
#[test]
fn relative_moves_add_up_exactly() {
    let mut b = Bench::flatbed_at(0, 0);
    b.ok("G91 G1 F1000");
    for _ in 0..2000 {
        b.ok("X0.0125");
    }
    assert_eq!(b.mpos()[0], 25_000);
    assert_eq!(b.steps()[0], 1000);
    b.ok("G20");
    for _ in 0..2000 {
        b.ok("Y0.00049");
    }
    assert_eq!(b.interp.position()[1], 24_892_000);
    assert_eq!(b.steps()[1], 996);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(6))]

    /// 10 000 relative moves of any size: the steps are the sum of the
    /// words rounded once.
    #[test]
    fn ten_thousand_relative_moves_are_their_sum(
        words in prop::collection::vec((-30_000i64..30_000, 2u32..=6), 10_000),
        inch in any::<bool>(),
    ) {
        let mut b = Bench::new(Machine::Drum);
        b.cfg.axes[0].soft_limits = false;
        b.ok(if inch { "G20 G91 G1 F100" } else { "G21 G91 G1 F100" });
        let mut sum: i128 = 0;
        for (w, places) in &words {
            // w / 10^places units, written with `places` decimals.
            let sign = if *w < 0 { "-" } else { "" };
            let p = 10i64.pow(*places);
            let text = match places {
                0 => format!("X{sign}{}", w.abs()),
                _ => format!("X{sign}{}.{:0n$}", w.abs() / p, w.abs() % p, n = *places as usize),
            };
            b.ok(&text);
            sum += *w as i128 * 10i128.pow(6 - places);
        }
        // In nanometres; an inch is 25.4 mm.
        let nm = if inch { sum * 254 / 10 } else { sum };
        let spu = b.cfg.axes[0].steps_per_unit;
        let n = nm * spu.num as i128;
        let d = spu.den as i128 * 1_000_000;
        let expected = if n >= 0 { (n + d / 2) / d } else { -((-n + d / 2) / d) };
        if inch {
            // Inch words of 6 decimals round to the nanometre each.
            prop_assume!(words.iter().all(|(_, p)| *p <= 5));
        }
        prop_assert_eq!(b.steps()[0] as i128, expected);
        prop_assert_eq!(b.interp.position()[0] as i128, nm);
    }
}

/// On a plotter `M3`/`M4` with any `S` lower the pen to `pen_down`, `M5`
/// raises it, `M300 S` sets its angle; a line with X/Y and a pen `Z`
/// (gcodetools' `G01 X… Y… Z-0.1 F400`) sets the pen first, then moves.
#[test]
fn the_pen_from_spindle_words_and_z() {
    let mut b = Bench::flatbed_at(70, 0);
    let (up, down) = (b.cfg.pen.up_deg, b.cfg.pen.down_deg);
    b.ok("M3 S1000");
    assert_eq!(b.io.did, [Did::Pen(down)]);
    assert_eq!(b.gc(), "G0 G54 G17 G21 G90 G94 M3 M9 T0 F0 S1000");
    b.ok("M5");
    b.ok("M4 S12");
    b.ok("M300 S42");
    assert_eq!(b.io.did[1..], [Did::Pen(up), Did::Pen(down), Did::Pen(42)]);
    assert_eq!(b.gc(), "G0 G54 G17 G21 G90 G94 M4 M9 T0 F0 S12");
    b.io.did.clear();
    b.ok("G01 X10 Y20 Z-0.1 F400");
    assert_eq!(
        b.io.did,
        [
            Did::Pen(down),
            Did::Move([400, 800, 0], Feed::PerMinute(Milli(400_000)))
        ]
    );
    b.io.did.clear();
    b.ok("G00 Z5");
    assert_eq!(
        b.io.did,
        [Did::Pen(up), Did::Move([400, 800, 0], Feed::Rapid)]
    );
    // The pen follows the work Z, not the machine's.
    b.ok("G10 L20 P1 Z0");
    b.ok("G0 Z-1");
    assert_eq!(b.io.pen, Some(down));
    // The string-art machine has no pen: M3 is kept for $G, M300 refused.
    let mut s = Bench::new(Machine::StringArt);
    s.ok("M3 S100");
    assert!(s.io.did.is_empty());
    assert_eq!(s.err("M300 S30"), 20);
    assert_eq!(b.err("M300"), 28);
}

/// `M2`/`M30`: once the motion is done, Grbl's program end (`gcode.c`
/// line 1077): `G1 G17 G90 G94 G54 M5 M9`, the pen up, `[MSG:Pgm End]`.
#[test]
fn program_end_resets_what_grbl_resets() {
    let mut b = Bench::flatbed_at(70, 0);
    b.ok("G10 L2 P2 X1");
    b.ok("G55 G91 G18 G20 G93 M3 M8 S100 T2");
    b.ok("M30");
    assert_eq!(b.gc(), "G1 G54 G17 G20 G90 G94 M5 M9 T0 F0 S100");
    let n = b.io.did.len();
    assert_eq!(b.io.did[n - 2..], [Did::Pen(b.cfg.pen.up_deg), Did::End]);
    // M1: no optional-stop switch, so nothing; M0 holds.
    b.io.did.clear();
    b.ok("M1");
    assert!(b.io.did.is_empty());
    b.ok("M0");
    assert_eq!(b.io.did, [Did::Pause]);
}

/// `M17` on, `M18`/`M84` off once the motion is done; Marlin's `M18 S`/
/// `M84 S` only set the seconds until the drivers go off after motion
/// stands (0: never), and that `S` is no spindle speed.
#[test]
fn drivers_on_off_and_their_idle_delay() {
    let mut b = Bench::flatbed_at(70, 0);
    b.ok("S100");
    for (text, did) in [
        ("M17", Did::Drivers(true)),
        ("M18", Did::Drivers(false)),
        ("M84", Did::Drivers(false)),
        ("M18 S2.5", Did::IdleDelay(2500)),
        ("M84 S0", Did::IdleDelay(0)),
        ("M84 S7200", Did::IdleDelay(7_200_000)),
    ] {
        b.io.did.clear();
        b.ok(text);
        assert_eq!(b.io.did, [did], "{text}");
    }
    assert_eq!(b.gc(), "G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S100");
    // Negative seconds are Grbl's error 4, one on/off per line its 21.
    assert_eq!(b.err("M18 S-1"), 4);
    assert_eq!(b.err("M17 M18"), 21);
    // Marlin's `M18 X` (that driver only) is no move here: Grbl's 31.
    b.io.did.clear();
    assert_eq!(b.err("M18 X1"), 31);
    assert_eq!(b.err("M17 Y2"), 31);
    assert!(b.io.did.is_empty());
    // `$C`: checked, nothing switched.
    let mut p = Parser::new();
    let block = match p.push_all_test(b"M18 S5\n") {
        Some(Ok(Input::Block(block))) => block,
        other => panic!("{other:?}"),
    };
    let env = checking(&b.kin, &b.cfg);
    b.io.did.clear();
    b.interp.accept(&block, false, &env, &mut b.io).unwrap();
    assert_eq!(b.interp.run(&env, &mut b.io), Progress::Done);
    assert!(b.io.did.is_empty());
}

#[test]
fn g_shows_grbl_s_modes_feed_in_mm_per_minute() {
    let mut b = Bench::flatbed_at(70, 0);
    assert_eq!(b.gc(), "G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0");
    b.ok("G20 G1 F10");
    // Grbl keeps and shows the feed in mm/min.
    assert_eq!(b.gc(), "G1 G54 G17 G20 G90 G94 M5 M9 T0 F254 S0");
    assert_eq!(
        show(&b.interp.parser_state(true)),
        "G1 G54 G17 G20 G90 G94 M5 M9 T0 F10.0 S0"
    );
    b.ok("M7");
    b.ok("M8 T7");
    assert_eq!(b.gc(), "G1 G54 G17 G20 G90 G94 M5 M7 M8 T7 F254 S0");
    b.ok("G80 G91.1 G40 G49 G61 M9");
    assert_eq!(b.gc(), "G80 G54 G17 G20 G90 G94 M5 M9 T0 F254 S0");
    // A jog changes no mode.
    b.ok("G0");
    b.ok("$J=G91 G21 X1 F500");
    assert_eq!(b.gc(), "G0 G54 G17 G20 G90 G94 M5 M9 T0 F254 S0");
}

#[test]
fn tool_length_offset_moves_the_work_z() {
    let mut b = Bench::new(Machine::StringArt);
    b.ok("G43.1 Z2");
    assert_eq!(b.wco(), [0, 0, 2_000]);
    b.ok("G0 Z1");
    assert_eq!(b.mpos()[2], 3_000);
    b.ok("G49");
    assert_eq!(b.wco(), [0; 3]);
}

#[test]
fn arcs_end_on_the_exact_target() {
    let mut b = Bench::flatbed_at(70, 50);
    b.ok("G10 L20 P1 X0 Y0");
    b.ok("G2 X10.0125 Y0 I5.00625 J0 F600");
    assert!(b.moves() > 10);
    // 80.0125 mm at 40 steps/mm: 3200.5 → 3201, rounded once.
    assert_eq!(b.steps(), [3201, 2000, 0]);
}

#[test]
fn lines_wait_for_the_machine_and_check_mode_moves_nothing() {
    let mut b = Bench::flatbed_at(70, 0);
    let env_check = Allowed {
        motion: true,
        checking: true,
    };
    let mut p = Parser::new();
    let block = match p.push_all_test(b"G1 X10 F100 M114\n") {
        Some(Ok(Input::Block(b))) => b,
        other => panic!("{other:?}"),
    };
    let env = Env {
        kin: &b.kin,
        cfg: &b.cfg,
        allowed: env_check,
    };
    b.interp.accept(&block, false, &env, &mut b.io).unwrap();
    assert_eq!(b.interp.run(&env, &mut b.io), Progress::Done);
    assert_eq!(b.io.did, [Did::Report]);
    // The state is taken: the next line starts at X10.
    assert_eq!(b.mpos()[0], 10_000);
}

impl Parser {
    fn push_all_test(&mut self, bytes: &[u8]) -> Option<Result<Input, crate::gcode::Error>> {
        bytes.iter().filter_map(|&b| self.push(b)).last()
    }
}

/// A job owns the motion: reads are answered, anything that moves is
/// refused (taut's 71).
#[test]
fn a_job_owns_the_motion() {
    let mut b = Bench::new(Machine::StringArt);
    let mut p = Parser::new();
    for (text, refused) in [
        ("G0 X1", true),
        ("G92 X0", true),
        ("M17", true),
        ("M18", true),
        ("M84 S5", true),
        ("G91", false),
        ("M114", false),
    ] {
        let block = match p.push_all_test(format!("{text}\n").as_bytes()) {
            Some(Ok(Input::Block(b))) => b,
            other => panic!("{other:?}"),
        };
        let env = Env {
            kin: &b.kin,
            cfg: &b.cfg,
            allowed: Allowed {
                motion: false,
                checking: false,
            },
        };
        let r = b.interp.accept(&block, false, &env, &mut b.io);
        assert_eq!(r.is_err(), refused, "{text}: {r:?}");
    }
    let _ = "".to_string();
}

/// On the arm a straight move goes to the planner as pieces of at most
/// 2 mm along the pen's line, each with the path's start and the
/// inverse of its end: `F` is the pen's speed along them. The last ends
/// exactly on the target.
#[test]
fn the_arms_straight_moves_are_the_pens_pieces() {
    let mut b = Bench::new(Machine::Scara);
    b.ok("G0 X100 Y150");
    b.io.did.clear();
    b.ok("G1 X130 Y110 F600");
    let pieces = b.pieces();
    // 50 mm in pieces of at most 2 mm.
    assert_eq!(pieces.len(), 25);
    assert_eq!(b.moves(), 0);
    let mm = |x: i32, y: i32| [Milli(x), Milli(y), Milli(0)];
    for (p, feed) in &pieces {
        assert_eq!(p.start, mm(100_000, 150_000));
        assert_eq!(*feed, Feed::PerMinute(Milli(600_000)));
        assert_eq!(Ok((p.steps, p.frac)), b.kin.inverse_fine(&p.to));
    }
    assert_eq!(pieces[11].0.to, mm(114_400, 130_800));
    assert_eq!(pieces[24].0.to, mm(130_000, 110_000));
    // A rapid too, at the pen's top speed.
    b.ok("G0 X100 Y150");
    assert_eq!(b.pieces().last().unwrap().1, Feed::Rapid);
}

/// A line shorter than half a piece (each of a stream of tiny ones)
/// goes to the planner as its one piece at once, no path kept: the piece
/// a path of it gives, from the last line's end, as are lines at and past
/// that edge; a full planner makes it wait and it is queued once.
#[test]
fn a_tiny_line_is_its_one_piece() {
    for (machine, at, half) in [
        (Machine::Scara, (100_000, 150_000), 1000),
        (Machine::Whiteboard, (0, 0), 2500),
    ] {
        let mut b = Bench::new(machine);
        b.ok(&format!("G0 X{} Y{}", at.0 / 1000, at.1 / 1000));
        b.io.did.clear();
        let (mut x, mut y) = at;
        let steps = [
            (50, 0),
            (35, 35),
            (0, -50),
            (half - 1, 0),
            (1 - half, half - 1),
            (half, 0),
            (-half, -half),
        ];
        for (k, (dx, dy)) in steps.into_iter().enumerate() {
            b.io.refuse = (k % 2) as u32;
            let from = [Milli(x), Milli(y), Milli(0)];
            (x, y) = (x + dx, y + dy);
            b.ok(&format!(
                "G1 X{:.3} Y{:.3} F1500",
                x as f64 / 1000.0,
                y as f64 / 1000.0
            ));
            let pieces = b.pieces();
            assert_eq!(pieces.len(), k + 1, "{machine:?} {k}");
            let (p, feed) = pieces[k];
            let to = [Milli(x), Milli(y), Milli(0)];
            let path: Vec<Position> = Segmenter::new(&b.kin, from, &to, b.kin.piece_um()).collect();
            assert_eq!(
                (p.start, p.to, path),
                (from, to, std::vec![to]),
                "{machine:?} {k}"
            );
            assert_eq!(Ok((p.steps, p.frac)), b.kin.inverse_fine(&p.to));
            assert_eq!(feed, Feed::PerMinute(Milli(1_500_000)));
        }
    }
}

/// The arm's shoulder cannot follow round behind its base (x = 100,
/// y < −56): a move across there is refused whole with error:33 before
/// anything moves, straight or as an arc; round the front it goes.
#[test]
fn the_arm_refuses_a_move_behind_its_base() {
    let mut b = Bench::new(Machine::Scara);
    b.ok("G0 X50 Y-100");
    let queued = b.io.did.len();
    assert_eq!(b.err("G1 X150 Y-100 F600"), 33);
    assert_eq!(b.err("G0 X150 Y-100"), 33);
    // Half a circle round (100, −100) passes under the shoulder.
    assert_eq!(b.err("G3 X150 Y-100 I50 J0 F600"), 33);
    assert_eq!(b.io.did.len(), queued);
    assert_eq!(b.mpos()[..2], [50_000, -100_000]);
    // Out of reach altogether (300 mm from the shoulder).
    assert_eq!(b.err("G1 X100 Y250 F600"), 33);
    // Round the front: the other way round the same circle, then lines.
    b.ok("G2 X150 Y-100 I50 J0 F600");
    assert_eq!(b.err("G0 X50 Y-100"), 33);
    for line in ["G1 X150 Y100", "G1 X50 Y100", "G1 X50 Y-100"] {
        b.ok(line);
    }
    assert_eq!(b.mpos()[..2], [50_000, -100_000]);
}

/// The whiteboard's straight moves: pieces of at most 5 mm.
#[test]
fn the_whiteboards_straight_moves_are_the_pens_pieces() {
    let mut b = Bench::new(Machine::Whiteboard);
    b.ok("G1 X-200 Y150 F3000");
    let pieces = b.pieces();
    assert_eq!(pieces.len(), 50);
    assert_eq!(pieces[49].0.to[..2], [Milli(-200_000), Milli(150_000)]);
    assert!(pieces.iter().all(|(p, _)| p.start == [Milli(0); 3]));
}

#[test]
fn a_cleared_run_is_a_new_one() {
    let mut run = Run::new();
    run.todo = todo::LEG_0 | todo::PEN;
    run.pen = 30;
    run.dwell_ms = 5;
    run.legs = [[1; AXES]; 2];
    run.from = [2; AXES];
    run.feed = Feed::PerMinute(Milli(1000));
    run.clear();
    assert_eq!(run, Run::new());
}

/// Seed 003's raw-step lines: the pen first (only when it changes), then
/// one rapid move of the two motors by their steps from where the moves
/// before end; G-code after it starts where it ended.
#[test]
fn a_seed_line_moves_the_motors_by_raw_steps() {
    let mut b = Bench::new(Machine::Whiteboard);
    b.ok("+0615-0950n");
    let down = b.cfg.pen.down_deg;
    assert_eq!(
        b.io.did,
        [Did::Pen(down), Did::Move([615, -950, 0], Feed::Rapid)]
    );
    b.ok("-0015+0050N");
    assert_eq!(b.steps(), [600, -900, 0]);
    assert_eq!(b.io.did.len(), 4, "{:?}", b.io.did);
    b.ok("+0000+0000u");
    let n = b.io.did.len();
    assert_eq!(b.io.did[n - 2], Did::Pen(b.cfg.pen.up_deg));
    // The programmed position is where the chains now hold the pen: a
    // G-code move back to it moves nothing, one to 0 goes back to zero.
    let at = b.kin.forward(&[600, -900, 0]);
    let before = b.io.did.len();
    let mm = |m: Milli| m.0 as f64 / 1000.0;
    b.ok(&format!("G1 X{:.3} Y{:.3} F1000", mm(at[0]), mm(at[1])));
    assert!(b.pieces().len() <= 1 && b.io.did.len() <= before + 1);
    b.ok("G0 X0 Y0");
    let end = b.steps();
    assert!(end[0].abs() <= 1 && end[1].abs() <= 1, "{end:?}");
}

#[test]
fn a_seed_line_is_refused_past_the_soft_limits_or_the_reach() {
    let mut b = Bench::new(Machine::Whiteboard);
    b.cfg.axes[0].soft_limits = true;
    b.cfg.axes[0].travel = (Milli(-10_000), Milli(10_000));
    // 615 steps of the left chain alone move the pen ~25 mm right.
    assert_eq!(b.err("+0615+0000n"), ErrorKind::TravelExceeded as u8);
    assert_eq!(b.io.did, []);
    b.ok("+0100+0000n");
    // Neither chain can be longer than both together (1.2 m apart, ~0.85
    // m each at the origin: 9999 steps are 571 mm).
    let mut b = Bench::new(Machine::Whiteboard);
    b.ok("+9999-9999n");
    assert_eq!(b.err("+9999-9999n"), ErrorKind::InvalidTarget as u8);
    assert_eq!(b.steps(), [9999, -9999, 0]);
}

#[test]
fn a_seed_line_in_check_mode_moves_nothing() {
    let mut b = Bench::new(Machine::Whiteboard);
    let env = checking(&b.kin, &b.cfg);
    let mv = crate::seed::parse(b"+0615-0950n").unwrap();
    b.interp.accept_steps(&mv, &env, &mut b.io).unwrap();
    assert_eq!(b.interp.run(&env, &mut b.io), Progress::Done);
    assert_eq!(b.io.did, []);
    let refused = Env {
        allowed: Allowed {
            motion: false,
            checking: false,
        },
        ..env
    };
    assert_eq!(
        b.interp.accept_steps(&mv, &refused, &mut b.io),
        Err(ErrorKind::JobOwnsMotion)
    );
}

/// A print going on after a cut: its lines before the checkpoint's taken
/// in `$C` (nothing moves), then the pen up, a rapid from where homing
/// left the machine to the programmed position in machine coordinates
/// (`G92`, `G91` and inches taken into account), and the pen as the
/// lines left it.
#[test]
fn a_resumed_print_replays_its_lines_without_moving_then_travels_back_and_pens() {
    let mut b = Bench::new(Machine::Flatbed);
    let lines = [
        "G21 G90",
        "M5",
        "G0 X10 Y10",
        "G92 X0 Y0",
        "M3",
        "G20 G91 G1 X1 Y0.5 F20",
        "M0",
        "G4 P500",
    ];
    let env = checking(&b.kin, &b.cfg);
    for line in lines {
        let mut p = Parser::new();
        let block = match p.push_all_test(format!("{line}\n").as_bytes()) {
            Some(Ok(Input::Block(block))) => block,
            other => panic!("{other:?}"),
        };
        b.interp.accept(&block, false, &env, &mut b.io).unwrap();
        assert_eq!(b.interp.run(&env, &mut b.io), Progress::Done);
    }
    assert!(b.io.did.is_empty(), "{:?}", b.io.did);
    let (up, down) = (b.cfg.pen.up_deg, b.cfg.pen.down_deg);
    // Homed to (0, 0): pen up, then to 10 + 25.4, 10 + 12.7 mm.
    b.interp.travel_back(&[Milli(0); AXES], up);
    let env = Env {
        kin: &b.kin,
        cfg: &b.cfg,
        allowed: Allowed::ALL,
    };
    while b.interp.run(&env, &mut b.io) != Progress::Done {
        b.io.clock += 10;
    }
    let to = b
        .kin
        .inverse(&[Milli(35_400), Milli(22_700), Milli(0)])
        .unwrap();
    assert_eq!(b.io.did, [Did::Pen(up), Did::Move(to, Feed::Rapid)]);
    b.io.did.clear();
    b.interp.pen_back(up);
    while b.interp.run(&env, &mut b.io) != Progress::Done {
        b.io.clock += 10;
    }
    assert_eq!(b.io.did, [Did::Pen(down)]);
    // The modes are the file's: the next relative inch move goes on.
    b.io.did.clear();
    b.ok("X1");
    let to = b
        .kin
        .inverse(&[Milli(60_800), Milli(22_700), Milli(0)])
        .unwrap();
    assert_eq!(b.steps(), to);
}

/// A stream of 0.05 mm chords of a circle (the bench's) is joined into
/// moves whose every vertex lies within the arc tolerance: on the
/// flatbed ~25 lines a move at 20 mm (sagitta L²/8R = 10 µm at 1.26 mm),
/// fewer on the arm's 10 mm; each move ends on a line's exact target,
/// the last on the last line's once the input pauses.
#[test]
fn a_circles_tiny_chords_are_joined_within_the_tolerance() {
    for (m, c, r, per) in [
        (Machine::Flatbed, (40.0, 40.0), 20.0, 22..=26),
        (Machine::Whiteboard, (0.0, 0.0), 20.0, 22..=26),
        (Machine::Scara, (100.0, 150.0), 10.0, 15..=18),
    ] {
        let mut b = Bench::new(m);
        b.ok(&format!("G0 X{} Y{}", c.0 + r, c.1));
        b.io.did.clear();
        let step = 2.0f64 * (0.05f64 / (2.0 * r)).asin();
        let at = |k: usize| {
            let a = step * k as f64;
            let p = [c.0 + r * a.cos(), c.1 + r * a.sin()];
            p.map(|v| (v * 1000.0).round() as i32)
        };
        let n = 1200;
        for k in 1..=n {
            let p = at(k);
            b.stream(&format!(
                "G1 X{} Y{} F1500",
                p[0] as f64 / 1000.0,
                p[1] as f64 / 1000.0
            ))
            .unwrap();
        }
        b.interp.flush_soon();
        b.run_out();
        let ends: Vec<[i32; 2]> = match m {
            Machine::Flatbed => {
                b.io.did
                    .iter()
                    .filter_map(|d| match d {
                        Did::Move(s, _) => Some([s[0] * 25, s[1] * 25]),
                        _ => None,
                    })
                    .collect()
            }
            _ => b
                .pieces()
                .iter()
                .map(|(p, _)| [p.to[0].0, p.to[1].0])
                .collect(),
        };
        let moves = ends.len();
        assert!(per.contains(&(n / moves)), "{m:?}: {moves} moves");
        // Every vertex within 10 µm of its move (the flatbed's ends are
        // its steps: 25 µm each, rounded from the exact target).
        let mut k = 0;
        let mut from = at(0);
        for end in &ends {
            let first = k;
            while at(k) != *end && k < n && m != Machine::Flatbed
                || m == Machine::Flatbed
                    && (at(k)[0] - end[0]).abs().max((at(k)[1] - end[1]).abs()) > 12
            {
                k += 1;
            }
            for v in first..k {
                let (p, a, e) = (at(v), from, at(k));
                let (dx, dy) = ((e[0] - a[0]) as f64, (e[1] - a[1]) as f64);
                let off = ((p[0] - a[0]) as f64 * dy - (p[1] - a[1]) as f64 * dx).abs()
                    / (dx * dx + dy * dy).sqrt();
                assert!(off <= 10.0, "{m:?}: vertex {v} {off} µm off");
            }
            from = at(k);
            k += 1;
        }
        assert_eq!(k, n + 1, "{m:?}");
    }
}

/// Tiny lines at one feed make one move, queued before whatever does not
/// join it: a line at another feed, `M3`, a dwell, a seed line (its raw
/// steps from the joined move's end); `M114` and an `F` alone leave it
/// open. A card print's checkpoint follows only the lines that start a
/// move (`blocks_before`).
#[test]
fn joined_moves_are_queued_before_what_does_not_join() {
    let mut b = Bench::flatbed_at(10, 10);
    b.io.did.clear();
    let x = |k: i32| format!("{:.3}", 10.0 + 0.1 * k as f64);
    b.take(&format!("G1 X{} Y10 F600", x(1))).unwrap();
    assert_eq!(
        b.interp.blocks_before(),
        Some(0),
        "the first starts the move"
    );
    b.run_out();
    for k in 2..=4 {
        b.take(&format!("G1 X{}", x(k))).unwrap();
        assert_eq!(b.interp.blocks_before(), None, "joined");
        b.run_out();
    }
    b.stream("M114").unwrap();
    b.take("F600").unwrap();
    assert_eq!(b.interp.blocks_before(), None);
    b.run_out();
    assert_eq!(b.io.did, [Did::Report]);
    // Another feed: the joined move first (to X10.4: 416 steps), then
    // the line starts a join of its own.
    b.take(&format!("G1 X{} F900", x(5))).unwrap();
    assert_eq!(b.interp.blocks_before(), Some(1));
    b.run_out();
    assert_eq!(b.interp.blocks_before(), Some(0));
    assert_eq!(
        b.io.did[1..],
        [Did::Move([416, 400, 0], Feed::PerMinute(Milli(600_000)))]
    );
    // The pen waits for it.
    b.stream("M3").unwrap();
    let down = b.cfg.pen.down_deg;
    assert_eq!(
        b.io.did[2..],
        [
            Did::Move([420, 400, 0], Feed::PerMinute(Milli(900_000))),
            Did::Pen(down)
        ]
    );
    // A seed line counts its steps from the joined move's end.
    b.stream("G1 X10.6 F900").unwrap();
    b.stream("G1 X10.7").unwrap();
    assert_eq!(b.io.did.len(), 4);
    b.stream("+0010+0000n").unwrap();
    assert_eq!(
        b.io.did[4..],
        [
            Did::Move([428, 400, 0], Feed::PerMinute(Milli(900_000))),
            Did::Pen(down),
            Did::Move([438, 400, 0], Feed::Rapid)
        ]
    );
    // A dwell waits for the move; so does the end of the input.
    b.stream("G1 X11 F900").unwrap();
    b.stream("G1 X11.1").unwrap();
    b.stream("G4 P0").unwrap();
    assert_eq!(
        b.io.did[7],
        Did::Move([444, 400, 0], Feed::PerMinute(Milli(900_000)))
    );
    b.stream("G1 X11.2").unwrap();
    assert_eq!(b.io.did.len(), 8);
    b.interp.flush_soon();
    b.run_out();
    assert_eq!(
        b.io.did[8],
        Did::Move([448, 400, 0], Feed::PerMinute(Milli(900_000)))
    );
}

/// `$12=0`: no vertex may stray from a joined move, so nothing is joined:
/// each tiny line is its own move at once (the cone's sine would have no
/// tolerance to take its half µm from).
#[test]
fn an_arc_tolerance_of_zero_joins_nothing() {
    let mut b = Bench::flatbed_at(10, 10);
    b.cfg.arc_tolerance_um = 0;
    b.io.did.clear();
    for k in 1..=3 {
        b.stream(&format!("G1 X{:.3} Y10 F600", 10.0 + 0.1 * k as f64))
            .unwrap();
        assert!(!b.interp.joining());
        assert_eq!(b.moves(), k);
    }
}
