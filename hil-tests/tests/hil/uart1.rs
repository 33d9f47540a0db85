//! The second console on UART1 (an HC-05/HC-06 at 9600 baud): a job sent
//! there line by line while a sender on USB polls `?`; each line answered
//! on its own port only; `?`, `!`, `~` and Ctrl-X from UART1; a line half
//! typed on USB never mixed with UART1's lines.

use hil_tests::sim::Sim;
use hil_tests::{
    assert_ram_budget, boot_machine, is_log_line, log_tail, m114_counts, send_ok, steps_on_pins,
    Rng,
};
use std::time::Duration;

/// The flatbed (40 steps/mm on X and Y), UART1 on at its default 9600
/// baud from the Ctrl-X after `$machine=`: the greeting on both ports.
fn flatbed_with_uart1() -> Sim {
    let mut sim = boot_machine();
    assert_eq!(
        sim.uart1_bytes(),
        b"",
        "UART1 is off on the string-art machine"
    );
    send_ok(&mut sim, "$machine=flatbed", Duration::from_secs(2));
    send_ok(&mut sim, "$$", Duration::from_secs(2));
    assert!(sim.uart_text().contains("$uart1_baud=9600\n"));
    sim.uart_send(&[0x18]);
    let greeted = sim.run_until_uart1_contains("Grbl 1.1h", Duration::from_millis(300));
    assert_eq!(greeted, hil_tests::sim::Outcome::Done, "{}", log_tail(&sim));
    // 9600 8N1: 10 bits of 104 µs, 16 MHz, U2X: UBRR 207.
    assert_eq!(sim.uart1_byte_cycles(), 10 * 8 * 208);
    sim.run_for(Duration::from_millis(50));
    sim
}

/// Sends `line` on UART1 and runs until its reply; returns the reply text
/// (the lines up to `ok` or `error:N`).
fn uart1_line(sim: &mut Sim, line: &str) -> String {
    let from = sim.uart1_bytes().len();
    sim.uart1_send(format!("{line}\n").as_bytes());
    let done = |s: &Sim| {
        let t = String::from_utf8_lossy(&s.uart1_bytes()[from..]).into_owned();
        let t = t[..t.rfind('\n').map_or(0, |i| i + 1)].to_string();
        t.lines()
            .any(|l| l == "ok" || l.starts_with("error:"))
            .then_some(t)
    };
    sim.run_until(|s| done(s).is_some(), Duration::from_secs(30));
    done(sim).unwrap_or_else(|| {
        panic!(
            "{line:?}: no reply on UART1: {:?}\n{}",
            sim.uart1_text(),
            log_tail(sim)
        )
    })
}

fn uart1_ok(sim: &mut Sim, line: &str) {
    let reply = uart1_line(sim, line);
    assert!(reply.ends_with("ok\n"), "{line:?}: {reply:?}");
}

/// `M114`'s `Count X:… Y:…` steps, asked on UART1.
fn counts_on_uart1(sim: &mut Sim) -> [i64; 2] {
    let c = m114_counts(&uart1_line(sim, "M114"));
    [c[0], c[1]]
}

fn status_lines(text: &str) -> usize {
    text.lines().filter(|l| l.starts_with('<')).count()
}

/// Seeded: 50 random relative moves sent on UART1, each after the last
/// one's `ok` and a random pause, while USB asks `?` every 100 ms. Every
/// UART1 line is answered `ok` on UART1; USB gets a status report for
/// each `?` and no `ok`; `M114` and the pulses both equal the moves' sum.
#[test]
fn a_job_on_uart1_while_usb_polls_status() {
    for seed in 1..=2u64 {
        let mut rng = Rng::new(seed);
        let mut sim = flatbed_with_uart1();
        uart1_ok(&mut sim, "G91");
        let usb_from = sim.uart_bytes().len();
        let start_s = sim.time_s();
        let polls = 300;
        for k in 0..polls {
            let at = Duration::from_secs_f64(start_s + 0.05 + 0.1 * k as f64);
            sim.uart_send_at(at, b"?");
        }
        let mut sum = [0i64; 2];
        let mut at = [0i64; 2];
        for _ in 0..50 {
            // Steps, kept inside X's 0..140 mm travel.
            let d = [0, 1].map(|i| {
                let d = rng.below(400) as i64 - 200;
                if at[i] + d < 0 || at[i] + d > 5000 {
                    -d
                } else {
                    d
                }
            });
            for i in 0..2 {
                at[i] += d[i];
                sum[i] += d[i];
            }
            let f = 1000 + rng.below(3000);
            let mm = |s: i64| format!("{:.3}", s as f64 / 40.0);
            uart1_ok(&mut sim, &format!("G1 X{} Y{} F{f}", mm(d[0]), mm(d[1])));
            sim.run_for(Duration::from_millis(rng.below(60)));
        }
        uart1_ok(&mut sim, "G4 P0");
        let end_s = sim.time_s();
        assert!(
            end_s < start_s + 0.1 * polls as f64,
            "seed {seed}: the job outlasted the polls ({:.1} s)",
            end_s - start_s
        );
        // Done moving (a dwell waits for the moves), then the position
        // asked on UART1.
        let counts = counts_on_uart1(&mut sim);
        assert_eq!(
            counts,
            sum,
            "seed {seed}: M114\n{}\nUSB {}",
            sim.uart1_text(),
            log_tail(&sim)
        );
        let pins = steps_on_pins(&sim);
        assert_eq!([pins[0], pins[1]], sum, "seed {seed}: the pulses");
        let usb = sim.uart_text_from(usb_from);
        let asked = ((sim.time_s() - start_s - 0.05) / 0.1) as usize + 1;
        let mut reports = 0;
        for l in usb.lines() {
            match l {
                _ if l.starts_with("<") && l.ends_with('>') => reports += 1,
                _ if is_log_line(l) => {}
                _ => panic!("seed {seed}: USB got {l:?}\n{usb}"),
            }
        }
        assert!(
            reports + 1 >= asked.min(polls),
            "seed {seed}: {reports} reports for {asked} `?`"
        );
        assert_eq!(status_lines(&sim.uart1_text()), 0, "seed {seed}");
        assert_ram_budget(&sim);
    }
}

/// `?` from UART1 is answered there (its `Bf:` the 64-byte ring's room),
/// not on USB; `$I` there gives that ring's size for a sender to count
/// against.
#[test]
fn status_asked_on_uart1_is_answered_there() {
    let mut sim = flatbed_with_uart1();
    let info = uart1_line(&mut sim, "$I");
    assert!(info.contains(",64]\n"), "{info:?}");
    // `Bf:` in the report.
    uart1_ok(&mut sim, "$10=3");
    let (usb, bt) = (sim.uart_bytes().len(), sim.uart1_bytes().len());
    sim.uart1_send(b"?");
    sim.run_for(Duration::from_millis(200));
    let reply = String::from_utf8_lossy(&sim.uart1_bytes()[bt..]).into_owned();
    assert!(reply.starts_with("<Idle|"), "{reply:?}");
    assert!(reply.contains(",64|"), "{reply:?}");
    assert_eq!(status_lines(&sim.uart_text_from(usb)), 0);
    assert_ram_budget(&sim);
}

/// `!` from UART1 holds a move (the pulses stop, `?` says `Hold`), `~`
/// from UART1 resumes it to its end.
#[test]
fn hold_and_resume_from_uart1() {
    let mut rng = Rng::new(7);
    let mut sim = flatbed_with_uart1();
    uart1_ok(&mut sim, "G1 X100 F1200");
    sim.run_for(Duration::from_millis(500 + rng.below(1500)));
    sim.uart1_send(b"!");
    sim.run_for(Duration::from_millis(600));
    let held = steps_on_pins(&sim)[0];
    assert!(held > 0 && held < 4000, "{held}");
    sim.run_for(Duration::from_millis(500));
    assert_eq!(steps_on_pins(&sim)[0], held, "held");
    let bt = sim.uart1_bytes().len();
    sim.uart1_send(b"?");
    sim.run_for(Duration::from_millis(200));
    let reply = String::from_utf8_lossy(&sim.uart1_bytes()[bt..]).into_owned();
    assert!(reply.contains("<Hold:0|"), "{reply:?}");
    sim.uart1_send(b"~");
    sim.run_for(Duration::from_secs(6));
    assert_eq!(steps_on_pins(&sim)[0], 4000, "resumed to X100");
    assert_ram_budget(&sim);
}

/// Ctrl-X from UART1 stops a move at once: the pulses stop, both ports
/// get `ALARM:3` and the greeting.
#[test]
fn ctrl_x_from_uart1_stops() {
    let mut rng = Rng::new(11);
    let mut sim = flatbed_with_uart1();
    uart1_ok(&mut sim, "G1 X100 F1200");
    sim.run_for(Duration::from_millis(300 + rng.below(2000)));
    let (usb, bt) = (sim.uart_bytes().len(), sim.uart1_bytes().len());
    sim.uart1_send(&[0x18]);
    sim.run_for(Duration::from_millis(100));
    let stopped = steps_on_pins(&sim)[0];
    sim.run_for(Duration::from_millis(500));
    assert_eq!(steps_on_pins(&sim)[0], stopped, "stopped");
    assert!(stopped < 4000);
    for text in [
        sim.uart_text_from(usb),
        String::from_utf8_lossy(&sim.uart1_bytes()[bt..]).into_owned(),
    ] {
        assert!(text.contains("ALARM:3\n"), "{text:?}");
        assert!(text.contains("Grbl 1.1h"), "{text:?}");
    }
    assert_ram_budget(&sim);
}

/// Seeded: a line half typed on USB (no end yet) while UART1's lines run:
/// they are read and answered on UART1 meanwhile; the USB line, finished
/// later, is answered `ok` on USB, and each port's moves are its own.
#[test]
fn a_half_typed_usb_line_never_mixes_with_uart1_lines() {
    for seed in 1..=3u64 {
        let mut rng = Rng::new(seed);
        let mut sim = flatbed_with_uart1();
        let usb = sim.uart_bytes().len();
        // Absolute moves: X from USB, Y from UART1.
        let head = "G90 G1 X2";
        let cut = 1 + rng.below(head.len() as u64 - 1) as usize;
        sim.uart_send(&head.as_bytes()[..cut]);
        sim.run_for(Duration::from_millis(rng.below(50)));
        let mut y = 0;
        for _ in 0..5 {
            y = 1 + rng.below(20);
            uart1_ok(&mut sim, &format!("G90 G1 Y{y} F3000"));
            sim.run_for(Duration::from_millis(rng.below(100)));
        }
        let text = sim.uart_text_from(usb);
        assert!(
            !text.lines().any(|l| l == "ok" || l.starts_with("error")),
            "{text:?}"
        );
        sim.uart_send(format!("{}5 F3000\n", &head[cut..]).as_bytes());
        sim.run_until(
            |s| s.uart_text_from(usb).contains("ok\n"),
            Duration::from_secs(5),
        );
        assert!(
            sim.uart_text_from(usb).contains("ok\n"),
            "seed {seed}\n{}",
            log_tail(&sim)
        );
        // The moves queued are done.
        uart1_ok(&mut sim, "G4 P0");
        let pins = steps_on_pins(&sim);
        assert_eq!(
            [pins[0], pins[1]],
            [25 * 40, y as i64 * 40],
            "seed {seed}\n{}",
            log_tail(&sim)
        );
        assert_ram_budget(&sim);
    }
}

/// `taut-sim --at1` sends to UART1 at a simulated time, and the report's
/// `uart1` holds what UART1 said: on the flatbed (UART1 on from power-on)
/// the greeting, a status report and a line's `ok`, none of them on USB.
#[test]
fn taut_sim_sends_on_uart1_and_reports_it() {
    use hil_tests::board::{scratch, taut_sim};
    let dir = scratch("uart1-cli");
    let report = dir.join("report.json");
    let out = std::process::Command::new(taut_sim())
        .arg(hil_tests::firmware_elf())
        .args([
            "--machine",
            "flatbed",
            "--at1",
            "3:?",
            "--at1",
            "3.5:G4\\x20P0\\n",
        ])
        .args(["--for", "4", "--report"])
        .arg(&report)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let uart1 = json["uart1"].as_str().unwrap();
    assert!(uart1.starts_with("Grbl 1.1h"), "{uart1:?}");
    assert!(uart1.contains("\n<Idle|"), "{uart1:?}");
    assert!(uart1.ends_with(">\nok\n"), "{uart1:?}");
    let usb = json["uart"].as_str().unwrap();
    assert!(
        !usb.lines().any(|l| l == "ok" || l.starts_with('<')),
        "{usb:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `taut-sim --pty1` serves UART1 as a terminal of its own, as a
/// Bluetooth module's `/dev/rfcomm0`: a line typed there is answered
/// there, and `?` too.
#[test]
fn taut_sim_serves_uart1_on_a_terminal() {
    use hil_tests::board::{scratch, taut_sim, Terminal};
    use std::io::{BufRead, BufReader, Write};
    let dir = scratch("uart1-pty");
    let link = dir.join("rfcomm0");
    let mut child = std::process::Command::new(taut_sim())
        .arg(hil_tests::firmware_elf())
        .args(["--machine", "flatbed", "--for", "60", "--pty1"])
        .arg(&link)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let mut said = String::new();
    while !said.contains("UART1 (second console) on") {
        assert_ne!(err.read_line(&mut said).unwrap(), 0, "taut-sim: {said}");
    }
    let mut bt = Terminal::open(&link);
    bt.wait_for("Grbl 1.1h", Duration::from_secs(10));
    bt.send_ok("G4 P0", Duration::from_secs(20));
    let mut file = std::fs::OpenOptions::new().write(true).open(&link).unwrap();
    file.write_all(b"?").unwrap();
    bt.wait_for("<Idle|", Duration::from_secs(5));
    child.kill().unwrap();
    child.wait().unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
}
