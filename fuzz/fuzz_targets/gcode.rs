//! Arbitrary bytes into the G-code parser: it must never panic, must answer
//! every line end (`\n`, `\r`, `\r\n`) exactly once, and must parse a good line after any input.
#![no_main]

use libfuzzer_sys::fuzz_target;
use taut_logic::gcode::{Command, Input, Parser, Realtime};

fuzz_target!(|data: &[u8]| {
    let mut parser = Parser::new();
    for &b in data {
        match parser.push(b) {
            Some(Ok(Input::Realtime(r))) => assert_eq!(Realtime::from_byte(b), Some(r)),
            Some(result) => {
                assert!(b == b'\n' || b == b'\r');
                if let Err(e) = result {
                    assert!(e.column().is_some() && !e.message().is_empty());
                }
            }
            None => assert!(Realtime::from_byte(b).is_none()),
        }
    }
    let mut last = None;
    for &b in b"\rM400\n" {
        last = parser.push(b).or(last);
    }
    match last {
        Some(Ok(Input::Line(line))) => assert_eq!(line.command, Command::WaitIdle),
        other => panic!("no clean line after the input: {other:?}"),
    }
});
