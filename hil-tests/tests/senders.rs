//! Issue 12: a real sender drives the simulated Mega through a
//! pseudo-terminal, as it would drive `/dev/ttyACM0`: grbl-streamer (PyPI,
//! pinned, installed into a venv under `target/`) connects, streams a
//! 2 000-line file in character-counting mode while polling `?`, and ends
//! without an error; the path rebuilt from the step pulses passes through
//! every line's end point, in order.

use hil_tests::sim::pty::Pty;
use hil_tests::sim::Sim;
use hil_tests::{boot_machine, log_tail, send_ok, track, Rng};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::Duration;

const GRBL_STREAMER: &str = "grbl-streamer==2.0.2";

fn target_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/clients")
}

/// The venv's Python with grbl-streamer, installed the first time (said
/// on stderr).
fn grbl_streamer_python() -> PathBuf {
    let venv = target_dir().join("venv");
    let python = venv.join("bin/python");
    let has = |p: &Path| {
        Command::new(p)
            .args(["-c", "import grbl_streamer"])
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    };
    if !has(&python) {
        eprintln!("installing {GRBL_STREAMER} into {}", venv.display());
        let ok = Command::new("python3")
            .args(["-m", "venv"])
            .arg(&venv)
            .status()
            .is_ok_and(|s| s.success())
            && Command::new(venv.join("bin/pip"))
                .args(["install", "--quiet", GRBL_STREAMER])
                .status()
                .is_ok_and(|s| s.success());
        assert!(ok && has(&python), "could not install {GRBL_STREAMER}");
    }
    python
}

/// A flatbed's random walk of `n` short moves (0.2–1 mm, 40 steps/mm)
/// inside its travel, turning a little at each (so the planner blends
/// them and the stream, not the corners, sets the pace), as G-code lines,
/// and each line's end in steps.
fn random_walk(seed: u64, n: usize) -> (Vec<String>, Vec<[i64; 2]>) {
    let mut rng = Rng::new(seed);
    let (mut at, mut heading) = ([70.0f64, 50.0], 0.0f64);
    let (mut lines, mut ends) = (vec!["G21 G90".to_string()], Vec::new());
    lines.push("G0 X70 Y50".to_string());
    ends.push([2800, 2000]);
    while lines.len() < n {
        heading += rng.between(-0.3, 0.3);
        let len = rng.between(0.2, 1.0);
        let to = [
            ((at[0] + len * heading.cos()) * 1000.0).round() / 1000.0,
            ((at[1] + len * heading.sin()) * 1000.0).round() / 1000.0,
        ];
        if !(5.0..135.0).contains(&to[0]) || !(5.0..95.0).contains(&to[1]) {
            // Turn away from the edge.
            heading += std::f64::consts::FRAC_PI_2;
            continue;
        }
        let f = if lines.len() == 2 { " F3000" } else { "" };
        lines.push(format!("G1 X{:.3} Y{:.3}{f}", to[0], to[1]));
        ends.push([(to[0] * 40.0).round() as i64, (to[1] * 40.0).round() as i64]);
        at = to;
    }
    (lines, ends)
}

/// Serves `sim` on a pseudo-terminal while `client` runs, given the
/// terminal's path then `args`; its output. Real time: the client sees a
/// Mega on USB.
fn serve(sim: &mut Sim, client: &mut Command, args: &[&str], limit: Duration) -> Output {
    let link = std::env::temp_dir().join(format!("taut-hil-tty-{}", std::process::id()));
    let mut pty = Pty::open(Some(&link)).unwrap();
    let mut child = client
        .arg(&link)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = sim.time_s();
    while child.try_wait().unwrap().is_none() {
        pty.serve(sim, Duration::from_millis(5)).unwrap();
        if sim.time_s() - start > limit.as_secs_f64() + 10.0 {
            let _ = child.kill();
            panic!("the client ran over {limit:?}\n{}", log_tail(sim));
        }
    }
    let out = child.wait_with_output().unwrap();
    if let Ok(dump) = std::env::var("TAUT_DUMP_RX") {
        std::fs::write(dump, pty.received()).unwrap();
    }
    out
}

#[test]
fn grbl_streamer_streams_2000_lines_counting_characters_and_the_pulses_follow() {
    let python = grbl_streamer_python();
    let n = std::env::var("TAUT_WALK").map_or(2000, |v| v.parse().unwrap());
    let (lines, ends) = random_walk(7, n);
    let file = target_dir().join(format!("walk-{}.gcode", std::process::id()));
    std::fs::write(&file, lines.join("\n") + "\n").unwrap();
    let mut sim = boot_machine();
    for line in ["$machine=flatbed", "$homing_at_start=0", "M17"] {
        send_ok(&mut sim, line, Duration::from_secs(2));
    }
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("clients/grbl_streamer_client.py");
    let mut client = Command::new(python);
    client.arg(script);
    let limit = Duration::from_secs(120);
    let args = [file.to_str().unwrap(), &limit.as_secs().to_string()];
    let out = serve(&mut sim, &mut client, &args, limit);
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
    // Every line's end, in order, on the path the pulses made.
    let path: Vec<[i64; 2]> = track(&sim).iter().map(|(_, s)| [s[0], s[1]]).collect();
    let mut at = 0;
    for (i, end) in ends.iter().enumerate() {
        match path[at..].iter().position(|p| p == end) {
            Some(k) => at += k,
            None => panic!(
                "line {} ends at {end:?}, never reached after pulse {at}",
                i + 2
            ),
        }
    }
    assert_eq!(
        path.last(),
        ends.last(),
        "the last line's end is where it stands"
    );
    // The step queue's health under this load, reported (not judged
    // here: the planner, not the protocol, decides it).
    let late = sim
        .uart_text()
        .lines()
        .rfind(|l| l.contains("underruns"))
        .map(str::to_owned);
    eprintln!(
        "{} pulses; {}",
        path.len(),
        late.as_deref().unwrap_or("no underruns")
    );
}
