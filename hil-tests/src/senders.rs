//! Shared by the tests in which a real sender (grbl-streamer, CNCjs) drives
//! the simulated Mega through a pseudo-terminal: where the clients are
//! installed, a flatbed job of short moves, serving the simulator to a
//! client in real time, and the check that the pulses followed the job.

use crate::sim::pty::Pty;
use crate::sim::Sim;
use crate::{log_tail, track, Rng};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::Duration;

/// Where the real clients are installed (`target/clients/`).
pub fn clients_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/clients")
}

/// The real senders installed (`hil-tests/clients/install.sh`: pinned,
/// idempotent, says what it installs): grbl-streamer's venv and CNCjs's
/// npm prefix, under [`clients_dir`]. Several tests may ask at once: one
/// installs, the others wait for it.
pub fn install_clients() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let ok = Command::new(client_script("install.sh"))
            .status()
            .is_ok_and(|s| s.success());
        assert!(ok, "hil-tests/clients/install.sh failed");
    });
}

/// A client script of `hil-tests/clients/`.
pub fn client_script(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("clients")
        .join(name)
}

/// A flatbed's random walk of `n` short moves (0.2–1 mm, 40 steps/mm)
/// inside its travel, turning a little at each (so the planner blends
/// them and the stream, not the corners, sets the pace), as G-code lines,
/// and each line's end in steps.
pub fn random_walk(seed: u64, n: usize) -> (Vec<String>, Vec<[i64; 2]>) {
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
/// Mega on USB. After every slice of simulated time, `each` is given the
/// simulator, the bytes the client wrote in that slice and the cycle at
/// which they were handed to the UART.
pub fn serve(
    sim: &mut Sim,
    client: &mut Command,
    args: &[&str],
    limit: Duration,
    mut each: impl FnMut(&Sim, &[u8], u64),
) -> Output {
    // One link a call: tests of one binary run side by side.
    static SERVED: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
    let n = SERVED.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let name = format!("taut-hil-tty-{}-{n}", std::process::id());
    let link = std::env::temp_dir().join(name);
    let mut pty = Pty::open(Some(&link)).unwrap();
    let mut child = client
        .arg(&link)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Read the pipes as the client writes them, so a chatty client never
    // blocks on a full pipe.
    let pipe = |mut r: Box<dyn std::io::Read + Send>| {
        std::thread::spawn(move || {
            let mut out = Vec::new();
            let _ = r.read_to_end(&mut out);
            out
        })
    };
    let stdout = pipe(Box::new(child.stdout.take().unwrap()));
    let stderr = pipe(Box::new(child.stderr.take().unwrap()));
    let start = sim.time_s();
    let mut seen = 0;
    while child.try_wait().unwrap().is_none() {
        let at = sim.cycles();
        pty.serve(sim, Duration::from_millis(5)).unwrap();
        each(sim, &pty.received()[seen..], at);
        seen = pty.received().len();
        if sim.time_s() - start > limit.as_secs_f64() + 10.0 {
            let _ = child.kill();
            panic!("the client ran over {limit:?}\n{}", log_tail(sim));
        }
    }
    let status = child.wait().unwrap();
    if let Ok(dump) = std::env::var("TAUT_DUMP_RX") {
        std::fs::write(dump, pty.received()).unwrap();
    }
    Output {
        status,
        stdout: stdout.join().unwrap(),
        stderr: stderr.join().unwrap(),
    }
}

/// The client sent every move of the job once, in order: the ends (in
/// steps, as [`random_walk`] gives them) of the lines with `X` and `Y`
/// words among the bytes it `wrote`, real-time bytes left out. A client
/// that skips or repeats a line fails here, before the pulses are blamed.
pub fn assert_sent_in_order(client: &str, wrote: &[u8], ends: &[[i64; 2]]) {
    let text: String = wrote
        .iter()
        .filter(|&&b| b.is_ascii() && !matches!(b, b'?' | b'!' | b'~' | 0x18))
        .map(|&b| b as char)
        .collect();
    let word = |line: &str, letter: char| {
        let at = line.find(letter)? + 1;
        let end = line[at..]
            .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
            .map_or(line.len(), |k| at + k);
        line[at..end].parse::<f64>().ok()
    };
    let sent: Vec<[i64; 2]> = text
        .lines()
        .filter(|l| !l.starts_with('$'))
        .filter_map(|l| Some([word(l, 'X')?, word(l, 'Y')?]))
        .map(|[x, y]| [(x * 40.0).round() as i64, (y * 40.0).round() as i64])
        .collect();
    if let Some(i) = (0..sent.len().max(ends.len())).find(|&i| sent.get(i) != ends.get(i)) {
        panic!(
            "{client} sent move {} as {:?}, the file has {:?} (line {}): the client skipped or repeated a line",
            i + 1,
            sent.get(i),
            ends.get(i),
            i + 2
        );
    }
}

/// The path rebuilt from the step pulses (base and radial, i.e. X and Y)
/// passes through every line's end in `ends`, in order, and stands at the
/// last; the path. A line joined with the next into one move (its end
/// within the arc tolerance, 10 µm, of the move: `docs/console.md`) is
/// passed within a step of its end, as the move's steps round.
pub fn assert_path_through(sim: &mut Sim, ends: &[[i64; 2]]) -> Vec<[i64; 2]> {
    let path: Vec<[i64; 2]> = track(sim).iter().map(|(_, s)| [s[0], s[1]]).collect();
    let mut at = 0;
    let near = |p: &[i64; 2], end: &[i64; 2]| (p[0] - end[0]).abs().max((p[1] - end[1]).abs()) <= 1;
    for (i, end) in ends.iter().enumerate() {
        let reached = path[at..]
            .iter()
            .position(|p| p == end)
            .or_else(|| path[at..].iter().position(|p| near(p, end)));
        match reached {
            Some(k) => at += k,
            None => {
                // What tells a lost byte from a lost step: the queues'
                // counts (the receive ring's refusals) and where the path
                // went instead.
                let near = path[at..]
                    .iter()
                    .min_by_key(|p| (p[0] - end[0]).abs() + (p[1] - end[1]).abs());
                let from = sim.uart_bytes().len();
                let _ = sim.send_line("$Q", std::time::Duration::from_secs(1));
                panic!(
                    "line {} ends at {end:?}, never reached after pulse {at} (nearest {near:?})\n{}",
                    i + 2,
                    sim.uart_text_from(from)
                )
            }
        }
    }
    assert_eq!(
        path.last(),
        ends.last(),
        "the last line's end is where it stands"
    );
    path
}

/// The step queue's health under a stream, as the firmware last reported
/// it (`… underruns:N`), for the test's log.
pub fn underruns(sim: &Sim) -> String {
    sim.uart_text()
        .lines()
        .rfind(|l| l.contains("underruns"))
        .map_or("no underruns".to_string(), str::to_owned)
}
