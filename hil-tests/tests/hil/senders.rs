//! A real sender drives the simulated Mega through a
//! pseudo-terminal, as it would drive `/dev/ttyACM0`: grbl-streamer (PyPI,
//! pinned, installed into a venv under `target/`) connects, streams a
//! 2 000-line file in character-counting mode while polling `?`, and ends
//! without an error; the path rebuilt from the step pulses passes through
//! every line's end point, in order.

use hil_tests::senders::{
    assert_path_through, assert_sent_in_order, client_script, clients_dir, install_clients,
    random_walk, serve, underruns,
};
use hil_tests::{boot_machine, send_ok};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// The venv's Python with grbl-streamer (installed by `install_clients`).
fn grbl_streamer_python() -> PathBuf {
    install_clients();
    clients_dir().join("venv/bin/python")
}

#[test]
fn grbl_streamer_streams_2000_lines_counting_characters_and_the_pulses_follow() {
    let python = grbl_streamer_python();
    let n = std::env::var("TAUT_WALK").map_or(2000, |v| v.parse().unwrap());
    let (lines, ends) = random_walk(7, n);
    let file = clients_dir().join(format!("walk-{}.gcode", std::process::id()));
    std::fs::write(&file, lines.join("\n") + "\n").unwrap();
    let mut sim = boot_machine();
    for line in ["$machine=flatbed", "$homing_at_start=0", "M17"] {
        send_ok(&mut sim, line, Duration::from_secs(2));
    }
    let script = client_script("grbl_streamer_client.py");
    let mut client = Command::new(python);
    client.arg(script);
    let limit = Duration::from_secs(120);
    let args = [file.to_str().unwrap(), &limit.as_secs().to_string()];
    let mut wrote = Vec::new();
    let out = serve(&mut sim, &mut client, &args, limit, |_, bytes, _| {
        wrote.extend_from_slice(bytes)
    });
    std::fs::remove_file(&file).unwrap();
    let said =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        let from = sim.uart_bytes().len();
        let _ = sim.send_line("$Q", Duration::from_secs(1));
        let queues = sim.uart_text_from(from);
        panic!("{said}\n{queues}");
    }
    eprintln!("{}", said.trim());
    assert_sent_in_order("grbl-streamer", &wrote, &ends);
    // Every line's end, in order, on the path the pulses made.
    let path = assert_path_through(&mut sim, &ends);
    // The step queue's health under this load, reported (not judged
    // here: the planner, not the protocol, decides it).
    eprintln!("{} pulses; {}", path.len(), underruns(&sim));
}

/// `taut send` (studio/): the debug binary, whose dependencies the host
/// unit tests have already built (a release build of them took minutes).
fn taut_bin() -> PathBuf {
    hil_tests::host_bin("taut")
}

/// Runs `taut send FILE <extra> --port <pty>` against a booted flatbed;
/// its output (stdout and stderr) and exit status.
fn taut_send(sim: &mut hil_tests::sim::Sim, file: &Path, extra: &[&str]) -> (bool, String) {
    let mut client = Command::new(taut_bin());
    client.args(["send", file.to_str().unwrap()]);
    client.args(extra).arg("--port");
    let out = serve(
        sim,
        &mut client,
        &[],
        Duration::from_secs(180),
        |_, _, _| {},
    );
    let said =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    (out.status.success(), said)
}

fn flatbed() -> hil_tests::sim::Sim {
    let mut sim = boot_machine();
    for line in ["$machine=flatbed", "$homing_at_start=0", "M17"] {
        send_ok(&mut sim, line, Duration::from_secs(2));
    }
    sim
}

/// `taut send` streams the same 2 000-line walk as grbl-streamer, counting
/// characters, with the same result on the pulses (the ETA planned with
/// the figures the machine lists in `$$`: the flatbed's); a file with a
/// line the machine refuses ends with a non-zero status and that line
/// named; a line too long for Grbl's buffer is refused before anything is
/// sent.
#[test]
fn taut_send_streams_the_walk_and_fails_on_a_refused_line() {
    let (lines, ends) = random_walk(7, 2000);
    let file = clients_dir().join(format!("walk-send-{}.gcode", std::process::id()));
    std::fs::create_dir_all(clients_dir()).unwrap();
    // A comment and a blank line cost nothing on the wire.
    let text = format!("(walk, seed 7)\n\n{}\n", lines.join(" ; a step\n"));
    std::fs::write(&file, text).unwrap();
    let mut sim = flatbed();
    let started = Instant::now();
    let (ok, said) = taut_send(&mut sim, &file, &[]);
    let wall = started.elapsed();
    assert!(ok, "{said}\n{}", hil_tests::log_tail(&sim));
    assert!(!said.contains("error:"), "{said}");
    assert!(said.contains("2000 lines to the flatbed"), "{said}");
    assert!(
        said.contains("2000 of 2000 lines answered, 0 error(s)"),
        "{said}"
    );
    assert_path_through(&mut sim, &ends);
    eprintln!("{}\n{wall:?} wall; {}", said.trim(), underruns(&sim));

    // Line 3 is past the flatbed's 140 mm: refused before anything moves.
    std::fs::write(
        &file,
        "G21 G90\nG1 X10 Y10 F3000\nG1 X500 Y10\nG1 X20 Y10\n",
    )
    .unwrap();
    let mut sim = flatbed();
    let (ok, said) = taut_send(&mut sim, &file, &["--machine", "flatbed"]);
    assert!(!ok, "{said}");
    assert!(
        said.contains("line 3: G1X500Y10: error:15 Travel exceeded"),
        "{said}"
    );
    assert!(said.contains("4 of 4 lines answered, 1 error(s)"), "{said}");
    // The lines around it ran.
    assert_path_through(&mut sim, &[[400, 400], [800, 400]]);

    // Longer than the 127 bytes in flight can be: refused up front (no
    // port needed).
    std::fs::write(
        &file,
        format!("G21\nG1 X1{}\n", " ".repeat(60) + &"Y1".repeat(70)),
    )
    .unwrap();
    let out = Command::new(taut_bin())
        .args(["send", file.to_str().unwrap(), "--port", "/nonexistent"])
        .output()
        .unwrap();
    std::fs::remove_file(&file).unwrap();
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(said.contains("line 2: 144 characters"), "{said}");
}
