//! XON/XOFF flow control (`$flow=xonxoff`) on the release image: a
//! terminal's "send file" (the whole file written at once into a
//! pseudo-terminal whose tty has `IXON` on, so the host side stops at the
//! firmware's XOFF and goes on at its XON) of 300 moves that outrun the
//! machine is answered `ok` line by line and drawn to its last move. With
//! flow control off (the default, Grbl's character counting) the same
//! file loses bytes: the fault the flow control is for, checked first.

use hil_tests::senders::random_walk;
use hil_tests::sim::pty::Pty;
use hil_tests::sim::Sim;
use hil_tests::{assert_ram_budget, boot_machine, log_tail, send_ok, settle, track};
use std::io::{Read, Write};
use std::os::fd::AsRawFd;
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

const LINES: usize = 300;

/// What a terminal got back for a file written at once: its lines.
struct Sent {
    replies: Vec<String>,
}

/// Writes `file` at once through a pseudo-terminal served by `sim`, its
/// tty raw with `IXON` as `ixon` says, and reads the replies until `want`
/// `ok` or `error:` lines came or 5 s of quiet.
fn send_file(sim: &mut Sim, file: &str, ixon: bool, want: usize) -> Sent {
    static N: AtomicU32 = AtomicU32::new(0);
    let name = format!(
        "taut-flow-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    );
    let link = std::env::temp_dir().join(name);
    let mut pty = Pty::open(Some(&link)).unwrap();
    let mut tty = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(&link)
        .unwrap();
    // SAFETY: a termios filled by the call, on the terminal just opened.
    unsafe {
        let mut tio: libc::termios = std::mem::zeroed();
        assert_eq!(libc::tcgetattr(tty.as_raw_fd(), &mut tio), 0);
        libc::cfmakeraw(&mut tio);
        if ixon {
            tio.c_iflag |= libc::IXON;
        }
        // Reads return what came within 0.1 s.
        tio.c_cc[libc::VMIN] = 0;
        tio.c_cc[libc::VTIME] = 1;
        assert_eq!(libc::tcsetattr(tty.as_raw_fd(), libc::TCSANOW, &tio), 0);
    }
    let mut writer = tty.try_clone().unwrap();
    let bytes = file.as_bytes().to_vec();
    let write = std::thread::spawn(move || writer.write_all(&bytes).unwrap());
    let reader = std::thread::spawn(move || {
        let (mut text, mut quiet) = (Vec::new(), Instant::now());
        let mut buf = [0u8; 512];
        loop {
            let n = tty.read(&mut buf).unwrap_or(0);
            text.extend_from_slice(&buf[..n]);
            let replies = String::from_utf8_lossy(&text)
                .lines()
                .filter(|l| *l == "ok" || l.starts_with("error:"))
                .count();
            if n > 0 {
                quiet = Instant::now();
            }
            if replies >= want || quiet.elapsed() > Duration::from_secs(5) {
                return String::from_utf8_lossy(&text).into_owned();
            }
        }
    });
    while !reader.is_finished() {
        pty.serve(sim, Duration::from_millis(5)).unwrap();
    }
    write.join().unwrap();
    let text = reader.join().unwrap();
    Sent {
        replies: text.lines().map(str::to_string).collect(),
    }
}

/// The walk's lines as one file, and each move's end in steps.
fn walk() -> (String, Vec<[i64; 2]>) {
    let (lines, ends) = random_walk(7, LINES);
    (lines.iter().map(|l| format!("{l}\n")).collect(), ends)
}

fn oks(sent: &Sent) -> usize {
    sent.replies.iter().filter(|l| *l == "ok").count()
}

#[test]
fn a_file_sent_at_once_loses_bytes_without_flow_control() {
    let mut sim = boot_machine();
    send_ok(&mut sim, "$machine=flatbed", Duration::from_secs(2));
    let (file, _) = walk();
    let sent = send_file(&mut sim, &file, true, LINES);
    // Lines came out broken (errors), or whole ones vanished.
    assert!(
        oks(&sent) < LINES,
        "all {LINES} lines ok without flow control:\n{}",
        log_tail(&sim)
    );
}

#[test]
fn a_file_sent_at_once_is_answered_ok_line_by_line_with_xon_xoff() {
    let mut sim = boot_machine();
    send_ok(&mut sim, "$machine=flatbed", Duration::from_secs(2));
    send_ok(&mut sim, "$flow=xonxoff", Duration::from_secs(2));
    let (file, ends) = walk();
    assert_eq!(file.lines().count(), LINES);
    let sent = send_file(&mut sim, &file, true, LINES);
    let errors: Vec<&String> = sent
        .replies
        .iter()
        .filter(|l| l.starts_with("error:"))
        .collect();
    assert!(errors.is_empty(), "{errors:?}\n{}", log_tail(&sim));
    assert_eq!(oks(&sent), LINES, "{}", log_tail(&sim));
    // The firmware paused the host (the file did outrun the machine) and
    // let it go on each time.
    let out = sim.uart_bytes();
    let (xoff, xon) = (
        out.iter().filter(|&&b| b == 0x13).count(),
        out.iter().filter(|&&b| b == 0x11).count(),
    );
    assert!(xoff > 0 && xon >= xoff, "{xoff} XOFF, {xon} XON");
    settle(&mut sim);
    let at = track(&sim).last().unwrap().1;
    assert_eq!(at[..2], ends[ends.len() - 1][..], "the last move's end");
    // `$$` lists it; off again, Grbl's character counting.
    let from = sim.uart_bytes().len();
    send_ok(&mut sim, "$$", Duration::from_secs(2));
    assert!(sim.uart_text_from(from).contains("$flow=xonxoff\n"));
    send_ok(&mut sim, "$flow=off", Duration::from_secs(2));
    assert_ram_budget(&sim);
}
