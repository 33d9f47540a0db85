//! The real CNCjs (npm, pinned, installed under `target/`)
//! drives the simulated Mega through a pseudo-terminal, as it would drive
//! `/dev/ttyACM0`. Its server opens the terminal as a Grbl controller,
//! loads a job from its watch directory and streams it; a feed hold from
//! it stops the pulses until its cycle start; its Grbl state goes
//! Idle → Run → Hold → Run → Idle; the job ends with no error, and the path
//! rebuilt from the step pulses passes through every line's end, in order.
//! `hil-tests/clients/cncjs_client.js` plays CNCjs's web UI (sign in,
//! socket.io, the same commands its buttons send).

use hil_tests::senders::{
    assert_path_through, client_script, clients_dir, install_clients, random_walk, serve, underruns,
};
use hil_tests::{boot_machine, send_ok, settle, track};
use std::collections::VecDeque;
use std::path::PathBuf;
use std::process::Command;
use std::time::{Duration, Instant};

/// CNCjs's npm prefix (installed by `install_clients`).
fn cncjs_prefix() -> PathBuf {
    install_clients();
    clients_dir().join("cncjs")
}

/// When things happened, in simulated cycles.
#[derive(Default, Debug)]
struct Seen {
    /// CNCjs's feed hold `!` reached the UART.
    hold_sent: Option<u64>,
    /// The firmware first answered a `?` with `<Hold:0|…>` (hold
    /// complete) after it.
    hold_reported: Option<u64>,
    /// CNCjs's cycle start `~` reached the UART.
    resume_sent: Option<u64>,
}

/// The bytes of the lines a sender has written and the firmware not yet
/// answered (`ok` / `error:`): what character counting keeps under the
/// 128-byte receive buffer. Real-time bytes take no room.
#[derive(Default)]
struct InFlight {
    lines: VecDeque<usize>,
    line: usize,
    bytes: usize,
    max: usize,
    /// The sum and count of the figures seen while lines were in flight.
    sum: usize,
    samples: usize,
    answers: Vec<u8>,
}

impl InFlight {
    fn wrote(&mut self, bytes: &[u8]) {
        for &b in bytes {
            match b {
                b'?' | b'!' | b'~' | 0x80.. => {}
                // Ctrl-X empties the receive buffer.
                0x18 => {
                    self.lines.clear();
                    (self.line, self.bytes) = (0, 0);
                }
                b'\n' => {
                    self.lines.push_back(self.line + 1);
                    self.bytes += self.line + 1;
                    self.line = 0;
                }
                _ => self.line += 1,
            }
        }
        self.max = self.max.max(self.bytes + self.line);
        if self.bytes > 0 {
            self.sum += self.bytes;
            self.samples += 1;
        }
    }

    fn read(&mut self, out: &[u8]) {
        self.answers.extend_from_slice(out);
        while let Some(end) = self.answers.iter().position(|&b| b == b'\n') {
            let line: Vec<u8> = self.answers.drain(..=end).collect();
            if line.trim_ascii_end() == b"ok" || line.starts_with(b"error:") {
                self.bytes -= self.lines.pop_front().unwrap_or(0);
            }
        }
    }
}

#[test]
fn cncjs_streams_a_job_holds_and_resumes_it_and_the_pulses_follow() {
    let started = Instant::now();
    let prefix = cncjs_prefix();
    let installed = started.elapsed();
    let (lines, ends) = random_walk(12, 300);
    let file = clients_dir().join(format!("cncjs-walk-{}.gcode", std::process::id()));
    std::fs::write(&file, lines.join("\n") + "\n").unwrap();
    let mut sim = boot_machine();
    // The job starts where the machine stands (its first move is there).
    for line in ["$machine=flatbed", "$homing_at_start=0", "M17", &lines[1]] {
        send_ok(&mut sim, line, Duration::from_secs(2));
    }
    settle(&mut sim);
    let mut client = Command::new("node");
    client.arg(client_script("cncjs_client.js"));
    let limit = Duration::from_secs(60);
    let (timeout, hold_s) = (limit.as_secs().to_string(), "1".to_string());
    let args = [
        prefix.to_str().unwrap(),
        file.to_str().unwrap(),
        &timeout,
        &hold_s,
    ];
    let mut seen = Seen::default();
    let mut uart_seen = sim.uart_bytes().len();
    let (mut rx, mut in_flight, mut answered) = (Vec::new(), InFlight::default(), uart_seen);
    let out = serve(&mut sim, &mut client, &args, limit, |sim, wrote, at| {
        rx.extend_from_slice(wrote);
        in_flight.wrote(wrote);
        in_flight.read(&sim.uart_bytes()[answered..]);
        answered = sim.uart_bytes().len();
        if seen.hold_sent.is_none() && wrote.contains(&b'!') {
            seen.hold_sent = Some(at);
            uart_seen = sim.uart_bytes().len();
        } else if seen.hold_reported.is_some()
            && seen.resume_sent.is_none()
            && wrote.contains(&b'~')
        {
            seen.resume_sent = Some(at);
        }
        if seen.hold_sent.is_some() && seen.hold_reported.is_none() {
            let text = &sim.uart_bytes()[uart_seen..];
            if text.windows(7).any(|w| w == b"<Hold:0") {
                seen.hold_reported = Some(sim.cycles());
            }
        }
    });
    std::fs::remove_file(&file).unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let said = stdout.clone() + &String::from_utf8_lossy(&out.stderr);
    // Over 128: CNCjs itself sent past the receive buffer, which Grbl too
    // would refuse (seen only with the host so loaded that the simulator
    // fell behind real time, and CNCjs's timed polls went out on top).
    let over = match in_flight.max > 128 {
        true => " (past the 128-byte receive buffer: the client over-sent)",
        false => "",
    };
    assert!(
        out.status.success(),
        "{said}\nat most {} bytes of lines in flight{over}\n{}",
        in_flight.max,
        hil_tests::log_tail(&sim)
    );
    if std::env::var_os("TAUT_CNCJS_LOG").is_some() {
        eprintln!("{said}");
    }
    let events: Vec<(&str, &str)> = stdout
        .lines()
        .filter_map(|l| l.strip_prefix("cncjs: ")?.split_once(' '))
        .map(|(_, l)| l.split_once(' ').unwrap_or((l, "")))
        .collect();
    let of = |kind: &str| -> Vec<&str> {
        events
            .iter()
            .filter(|(k, _)| *k == kind)
            .map(|(_, v)| *v)
            .collect()
    };

    // CNCjs's Grbl state, as its UI shows it, until its Reset at the end:
    // Idle, Run, one Hold, Run again, Idle (a stream that falls behind the
    // planner may show Idle between Runs: Grbl does too).
    let states: Vec<&str> = events
        .iter()
        .take_while(|e| *e != &("command", "reset"))
        .filter(|(k, _)| *k == "state")
        .map(|(_, v)| *v)
        .collect();
    let hold = states.iter().position(|&s| s == "Hold");
    let ok = states.first() == Some(&"Idle")
        && states.last() == Some(&"Idle")
        && states.iter().all(|s| ["Idle", "Run", "Hold"].contains(s))
        && states.iter().filter(|&&s| s == "Hold").count() == 1
        && hold.is_some_and(|h| states[..h].contains(&"Run") && states[h..].contains(&"Run"));
    assert!(ok, "CNCjs's states {states:?}\n{said}");
    let workflow = of("workflow");
    assert_eq!(workflow, ["running", "idle"], "CNCjs's workflow\n{said}");
    // The whole file acknowledged (and CNCjs's own `%wait` line after it).
    let total = lines.len() + 1;
    assert!(
        of("sender").contains(&format!("{total}/{total}").as_str()),
        "the job was not acknowledged whole\n{said}"
    );
    let bad: Vec<&str> = of("read")
        .into_iter()
        .filter(|l| l.starts_with("error") || l.starts_with("ALARM"))
        .collect();
    assert!(bad.is_empty(), "{bad:?}\n{said}");

    // The pulses: under way when the hold is sent, none from the hold
    // being reported until the cycle start, and on again after it.
    let (hold_sent, hold_reported, resume_sent) = match seen {
        Seen {
            hold_sent: Some(a),
            hold_reported: Some(b),
            resume_sent: Some(c),
        } => (a, b, c),
        _ => panic!("hold and resume not seen: {seen:?}\n{said}"),
    };
    let cycles: Vec<u64> = track(&sim).iter().map(|(c, _)| *c).collect();
    let between = |from: u64, to: u64| cycles.iter().filter(|&&c| from <= c && c < to).count();
    let ms = |c: u64| c as f64 / 16e3;
    let before = between(hold_sent.saturating_sub(16_000_000 / 2), hold_sent);
    let slowing = between(hold_sent, hold_reported);
    let held = between(hold_reported, resume_sent);
    let after = between(resume_sent, resume_sent + 16_000_000 / 10);
    eprintln!(
        "hold sent at {:.0} ms, reported {:.0} ms later ({slowing} pulses), \
         held {:.0} ms ({held} pulses), resumed: {after} pulses in 100 ms",
        ms(hold_sent),
        ms(hold_reported - hold_sent),
        ms(resume_sent - hold_reported),
    );
    assert!(before > 0, "no pulses in the 500 ms before the hold");
    assert!(
        resume_sent - hold_reported > 16_000_000 / 2,
        "held for {:.0} ms only",
        ms(resume_sent - hold_reported)
    );
    assert_eq!(held, 0, "pulses during the hold");
    assert!(after > 0, "no pulses in the 100 ms after the cycle start");

    // Every line's end, in order, on the path the pulses made.
    let path = assert_path_through(&mut sim, &ends);

    // What CNCjs wrote besides the job: on connecting, then its polls.
    let rx = String::from_utf8_lossy(&rx);
    let job_at = rx
        .find(&format!("{}\n", lines[0]))
        .expect("the job's first line");
    let count = |what: &str| rx.matches(what).count();
    eprintln!(
        "CNCjs wrote before the job {:?}; in all {} `?`, {} `$G`, {} `$$`",
        &rx[..job_at],
        count("?"),
        count("$G\n"),
        count("$$\n")
    );
    assert!(count("?") >= 10, "CNCjs polls `?`");
    assert!(count("$G\n") >= 1, "CNCjs polls `$G`");
    // It opened the port after the banner (serialport flushes what came
    // before), so it asked `?` and was ready on the report: then `$$`.
    assert!(
        rx.starts_with("?$$\n"),
        "CNCjs began with {:?}",
        &rx[..job_at]
    );
    // Its Reset at the end: the banner, from which it took the version.
    assert_eq!(of("version"), ["1.1h"], "{said}");
    // Character counting, against the receive buffer.
    eprintln!(
        "CNCjs had at most {} bytes of lines unanswered ({} on average)",
        in_flight.max,
        in_flight.sum / in_flight.samples.max(1)
    );
    assert!(
        (64..=128).contains(&in_flight.max),
        "at most {} bytes in flight",
        in_flight.max
    );
    eprintln!(
        "{}; {} pulses; {}; {:.1} s (install {:.1} s)",
        of("done").join(" "),
        path.len(),
        underruns(&sim),
        started.elapsed().as_secs_f64(),
        installed.as_secs_f64()
    );
}

/// CNCjs's own buttons against the flatbed, as its Axes widget sends
/// them (CNCjs 1.11.5): a jog arrow (`G91`, `G0 X10 Y5`, `G90`), "Zero
/// Out Work Offsets" (`G10 L20 P1 X0 Y0 Z0`), another jog (`G91`, `G0
/// X-4`, `G90`), "Go To Work Zero" (`G0 X0 Y0 Z0`). The pulses go where
/// those say, from the middle of the bed, and `$#` and `?` keep the work
/// zero where it was set; the machine position never jumps.
#[test]
fn cncjs_zero_and_jog_buttons_move_the_machine_and_set_the_work_zero() {
    use hil_tests::steps_on_pins;
    let prefix = cncjs_prefix();
    let mut sim = boot_machine();
    for line in [
        "$machine=flatbed",
        "$homing_at_start=0",
        "M17",
        "G0 X70 Y30",
    ] {
        send_ok(&mut sim, line, Duration::from_secs(2));
    }
    settle(&mut sim);
    // 40 steps a mm on both axes.
    assert_eq!(steps_on_pins(&sim)[..2], [2800, 1200]);
    let from = sim.cycles();
    let buttons = "buttons:G91|G0 X10 Y5|G90|G10 L20 P1 X0 Y0 Z0|G91|G0 X-4|G90|G0 X0 Y0 Z0";
    let mut client = Command::new("node");
    client.arg(client_script("cncjs_client.js"));
    let args = [prefix.to_str().unwrap(), buttons, "60", "0"];
    let out = serve(
        &mut sim,
        &mut client,
        &args,
        Duration::from_secs(60),
        |_, _, _| {},
    );
    let said =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "{said}\n{}",
        hil_tests::log_tail(&sim)
    );
    assert!(said.contains("done buttons"), "{said}");
    settle(&mut sim);
    // Jogged to (80, 35), zeroed there, jogged to (76, 35), back to zero.
    assert_eq!(steps_on_pins(&sim)[..2], [3200, 1400]);
    let path: Vec<[i64; 3]> = track(&sim)
        .into_iter()
        .filter(|(c, _)| *c > from)
        .map(|(_, s)| s)
        .collect();
    let passes = |x: i64, y: i64| path.iter().any(|s| s[0] == x && s[1] == y);
    assert!(passes(3200, 1400) && passes(3040, 1400), "the jogs' ends");
    assert!(path
        .iter()
        .all(|s| s[1] >= 1200 && s[1] <= 1400 && s[0] >= 2800 && s[0] <= 3200));
    let start = sim.uart_bytes().len();
    send_ok(&mut sim, "$#", Duration::from_secs(2));
    let text = sim.uart_text_from(start);
    assert!(text.contains("[G54:80.000,35.000,0.000]\n"), "{text}");
    assert!(text.contains("[G92:0.000,0.000,0.000]\n"), "{text}");
    let start = sim.uart_bytes().len();
    sim.uart_send(b"?");
    sim.run_for(Duration::from_millis(50));
    let report = sim.uart_text_from(start);
    assert!(report.contains("MPos:80.000,35.000,0.000"), "{report}");
}
