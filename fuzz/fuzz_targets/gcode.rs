//! Arbitrary bytes into the G-code parser and the executor: neither may
//! panic (overflow checks are on) or loop; every line end (`\n`, `\r`,
//! `\r\n`) is answered exactly once; an error has a message; every block
//! is carried out against a machine that takes anything, to its end; a
//! seed-003 raw-step line reads back from its own text and is carried
//! out too; and a good line parses after any input.
#![no_main]

use libfuzzer_sys::fuzz_target;
use taut_logic::config::MachineConfig;
use taut_logic::coords::CoordData;
use taut_logic::gcode::{Input, Parser, Realtime};
use taut_logic::interp::{coords, Allowed, Env, Exact, Interpreter, MachineIo, Progress, Wait};
use taut_logic::kinematics::{AnyKinematics, Steps};
use taut_logic::machine::Machine;
use taut_logic::planner::Feed;

/// A machine that does at once whatever it is asked.
struct Yes {
    coords: CoordData,
    clock: u32,
    steps: Steps,
}

impl MachineIo for Yes {
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
        self.steps
    }
    fn queue(&mut self, steps: &Steps, _feed: Feed) -> bool {
        self.steps = *steps;
        true
    }
    fn idle(&mut self) -> bool {
        true
    }
    fn pen(&mut self, _deg: u8) -> bool {
        true
    }
    fn drivers(&mut self, _on: bool) {}
    fn idle_delay(&mut self, _ms: u32) {}
    fn pause(&mut self) {}
    fn report_position(&mut self) {}
    fn program_end(&mut self) {}
    fn millis(&self) -> u32 {
        self.clock
    }
}

fuzz_target!(|data: &[u8]| {
    // The first byte picks the machine: linear, hanging or an arm.
    let machine = match data.first().map(|b| b % 3) {
        Some(1) => Machine::Whiteboard,
        Some(2) => Machine::Scara,
        _ => Machine::Flatbed,
    };
    let cfg = MachineConfig::defaults(machine);
    let kin = AnyKinematics::of(&cfg).unwrap();
    let env = Env {
        kin: &kin,
        cfg: &cfg,
        allowed: Allowed::ALL,
    };
    let mut io = Yes {
        coords: CoordData::ZERO,
        clock: 0,
        steps: [0; 3],
    };
    let mut interp = Interpreter::new();
    let mut parser = Parser::new();
    for &b in data.iter().skip(1) {
        let (block, jog) = match parser.push(b) {
            Some(Ok(Input::Realtime(r))) => {
                assert_eq!(Realtime::from_byte(b), Some(r));
                continue;
            }
            None => {
                assert!(Realtime::from_byte(b).is_none());
                continue;
            }
            Some(result) => {
                assert!(b == b'\n' || b == b'\r' || b == taut_logic::gcode::LINE_CUT);
                match result {
                    Err(e) => {
                        assert!(!e.message().is_empty());
                        continue;
                    }
                    Ok(Input::Block(block)) => (block, false),
                    Ok(Input::Jog(block)) => (block, true),
                    Ok(Input::Seed(Some(mv))) => {
                        let mut again = Parser::new();
                        let text = mv.text();
                        let back = text.iter().chain(b"\n").find_map(|&b| again.push(b));
                        assert_eq!(back, Some(Ok(Input::Seed(Some(mv)))));
                        let accepted = interp.accept_steps(&mv, &env, &mut io).is_ok();
                        run_out(accepted, &mut interp, &env, &mut io);
                        continue;
                    }
                    Ok(_) => continue,
                }
            }
        };
        let accepted = interp.accept(&block, jog, &env, &mut io).is_ok();
        run_out(accepted, &mut interp, &env, &mut io);
    }
    let mut last = None;
    for &b in b"\rM400\n" {
        last = parser.push(b).or(last);
    }
    match last {
        Some(Ok(Input::Block(block))) => {
            assert_eq!(block.taut, taut_logic::gcode::TautCode::WaitIdle)
        }
        other => panic!("no clean line after the input: {other:?}"),
    }
});

/// An accepted line's actions carried out to their end.
fn run_out(accepted: bool, interp: &mut Interpreter, env: &Env<AnyKinematics>, io: &mut Yes) {
    if !accepted {
        return;
    }
    // Every action ends: a path has a bounded number of pieces.
    for _ in 0..1_000_000 {
        match interp.run(env, io) {
            Progress::Done => break,
            Progress::Wait(Wait::Ms(ms)) => io.clock = io.clock.wrapping_add(ms.into()),
            Progress::Wait(_) => {}
        }
    }
    interp.drop_line();
}
