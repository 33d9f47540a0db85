//! `taut-sim ELF [options]`: run a firmware image on the simulated machine
//! with every RAMPS pin probed under its fixed VCD name, then write the
//! trace and a JSON report. `cargo xtask sim` calls it with the release ELF.

use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use taut_logic::config::MachineConfig;
use taut_logic::machine::Machine;
use taut_logic::settings::eeprom::host;
use taut_simavr::clock::{cycles_in, FREQ_HZ};
use taut_simavr::operator::Seen;
use taut_simavr::pty::{Pace, Pty};
use taut_simavr::scenario::{self, FaultSpec, TimedBytes};
use taut_simavr::sdcard::{SdCard, SdImage};
use taut_simavr::session::{self, Ending, Plan, Session};
use taut_simavr::{picture, replay};
use taut_simavr::{Outcome, Reply, Sim};

const USAGE: &str = "\
usage: taut-sim ELF [options]
       taut-sim [ELF] --bootloader HEX --pty [PATH] [options]
       [--sd DIR_OR_IMAGE [--sd-insert-at SECONDS]
                   [--pull-card-at SECONDS]... [--reinsert-at SECONDS]...
                   [--card-fault SPEC]...] [--auto-confirm] [--send FILE]
                   [--at SECONDS:BYTES]... [--for SECONDS] [--vcd PATH]
                   [--png PATH] [--report PATH] [--eeprom FILE] [--echo]
                   [--power-cut-at SECONDS | --power-cut-on TEXT
                   [--power-cut-delay SECONDS]]
                   [--machine NAME [--endstop-mm MM]] [--pty [PATH]]
                   [--at1 SECONDS:BYTES]... [--pty1 [PATH]]
                   [--bootloader HEX]
  ELF             the firmware, loaded into flash as a debugger would (reset
                  at address 0); with --bootloader, the application already
                  flashed beside the bootloader (optional)
  --bootloader HEX
                  a Mega 2560 as sold: the bootloader (Intel hex, e.g.
                  /usr/share/arduino/hardware/arduino/avr/bootloaders/
                  stk500v2/stk500boot_v2_mega2560.hex) in the boot section,
                  its fuses (BOOTRST: every reset starts the bootloader) and
                  lock bits (SPM cannot write the boot section); each open
                  of the --pty terminal resets the board, as the Mega's
                  auto-reset does on DTR, so avrdude -c wiring (and
                  ravedude) flash it through the terminal; time runs as
                  fast as the host can while bytes are on the line and in
                  step with the wall clock when it is idle
  --sd PATH       put a virtual SD card in the slot: an image file, or a
                  folder, imaged on the fly (FAT16 or FAT32 by size)
  --sd-insert-at SECONDS
                  insert that card later instead of at power-on
  --pull-card-at SECONDS
                  take the card out at that simulated time: from then on
                  the slot is empty (MISO reads high); repeatable
  --reinsert-at SECONDS
                  put the same card back (what was written to it and its
                  faults not yet triggered kept); it powers up afresh, as a
                  card does when it goes in; repeatable, each after a pull
  --card-fault SPEC
                  a fault of the card; repeatable. SPEC is one of
                    crc-once:BLOCK     the next read of BLOCK has a bad CRC16,
                                       once; later reads are fine
                    bad-block:BLOCK    every read of BLOCK fails as a worn-out
                                       block does: R1 fine, then data error
                                       token 0x04 (card ECC failed)
                    crc-once-at:SECONDS  the first data block the card sends
                                       after that time has a bad CRC16
                  BLOCK is a block number (LBA, decimal or 0x hex) or a file
                  name in the card's root folder: its first data block
  --send FILE     stream FILE's lines to the serial console, each after the
                  previous one's ok/error, then run until motion is idle
  --at SECONDS:BYTES
                  send BYTES to the serial console at that simulated time,
                  without waiting for any reply, ahead of a --send line still
                  on its way (as a sender's real-time commands: ? ! ~ and
                  Ctrl-X \\x18); escapes \\xHH \\n \\r \\t \\0 \\\\; repeatable.
                  A whole G-code line sent so gets its own ok, which --send
                  may take for its line's: use lines without --send
  --for SECONDS   simulated time to run (default 5; with --send: extra time
                  after motion is idle, default 0; with --auto-confirm or
                  --pty: no limit). Without --for the run also goes on
                  until 1 s after the last planned event (--at,
                  --pull-card-at, --reinsert-at, crc-once-at). A planned
                  power cut outlasts it: the run lasts until the cut
  --at1 SECONDS:BYTES
                  the same for UART1, the second console (a Bluetooth
                  module's, at the rate the firmware set: 9600 by default);
                  the firmware turns it on on a plotter or the arm
  --vcd PATH      write a VCD trace of every probed pin, named by the
                  machine's channels (base_, radial_, drill_; x_, y_;
                  left_, right_; shoulder_, elbow_), the ULN2003 coil
                  inputs (x_in1..x_in4, y_in*, z_in*) and pen_pwm
  --png PATH      draw from the step pulses alone: the string-art job (the
                  board from the card's param.txt; needs --sd), or a
                  plotter's drawing (pen down dark, travel faint blue)
  --machine NAME  power on as this machine (string_art, drum, flatbed,
                  whiteboard, scara) with its defaults in EEPROM
  --endstop-mm MM where the MIN switches of the machine's homing axes
                  close: MM below where each axis stands at power-on
                  (default 3); homing at power-on and G28 find them there
  --pty [PATH]    serve the serial port as a pseudo-terminal (its path is
                  printed; PATH, if given, becomes a symbolic link to it)
                  for senders and terminals, in real time; runs until
                  --for SECONDS, or SIGINT / SIGTERM, then writes the VCD,
                  the picture and the report as any run does
  --pty1 [PATH]   serve UART1 (the second console) as a pseudo-terminal
                  too, as a Bluetooth module's /dev/rfcomm0 is (--pty, with
                  no link, if not given)
  --profile N     print the N functions the MCU spent the most cycles in
  --report PATH   write a JSON report (cycles, time, outcome, UART, pin figures)
  --eeprom FILE   the EEPROM's contents (settings): loaded at power-on if the
                  file exists, saved when the run ends (a power cycle keeps
                  only the EEPROM: run again with the same file)
  --power-cut-at SECONDS
                  cut the power at that simulated time, to the cycle (the
                  MCU stops on the first instruction boundary at or past
                  it): the run ends there, the VCD and the report are
                  written (\"ended\": \"power cut\", with the cycle) and
                  --eeprom saves the EEPROM as the cut leaves it (a byte
                  still being written, within its 3.4 ms, left erased); run
                  again with the same --eeprom to resume
  --power-cut-on TEXT
                  cut the power --power-cut-delay after the firmware's
                  serial output first holds TEXT (from the cycle its last
                  byte left the UART; under --pty, within 10 ms); the run
                  lasts until the cut. A run whose TEXT never appears ends
                  with an error
  --power-cut-delay SECONDS
                  simulated seconds from TEXT to the cut (default 0)
  --auto-confirm  press the green button whenever the job asks for it, take
                  a resume offer and zero the axes again after a power cut
                  (in the simulator they are still at the zero pose), and
                  run until the job (the string-art job, or a print from
                  the card) is done, however long; --for SECONDS limits it
                  (a job cut short by it is exit status 3)
  --echo          print the firmware's serial output as it runs
  --help, -h      this text
Times are simulated seconds since power-on (0.25, 3).
The last line says how the run ended: job finished, time limit reached,
stopped by the time limit at (how far the job got), power cut at cycle N,
alarm (ALARM:n, under a job), firmware fault, stopped by a signal.
Exit status: 0 as asked (job finished, cut made, limit of a run with no job
under way, a signal); 1 a firmware fault, a cut that never came, or an
error; 2 bad options; 3 a job cut short by the limit; 4 an alarm under a
job.";

struct Args {
    elf: Option<PathBuf>,
    bootloader: Option<PathBuf>,
    sd: Option<PathBuf>,
    sd_insert_at: Option<Duration>,
    pulls: Vec<Duration>,
    reinserts: Vec<Duration>,
    faults: Vec<FaultSpec>,
    send: Option<PathBuf>,
    at: Vec<TimedBytes>,
    /// `--at1`: the same for USART1, the second console.
    at1: Vec<TimedBytes>,
    seconds: Option<Duration>,
    vcd: Option<PathBuf>,
    png: Option<PathBuf>,
    report: Option<PathBuf>,
    eeprom: Option<PathBuf>,
    machine: Option<Machine>,
    endstop_mm: f64,
    echo: bool,
    auto_confirm: bool,
    /// `--pty`, and the link to make, if any.
    pty: Option<Option<PathBuf>>,
    /// `--pty1`: USART1's terminal, and its link.
    pty1: Option<Option<PathBuf>>,
    /// `--profile N`: the top N functions by cycles.
    profile: Option<usize>,
    cut: Option<Cut>,
    cut_delay: Duration,
}

/// When the power goes.
enum Cut {
    At(Duration),
    On(String),
}

fn parse(it: impl Iterator<Item = String>) -> Result<Args, String> {
    let mut it = it.peekable();
    let elf = it.next_if(|a| !a.starts_with("--")).map(PathBuf::from);
    let mut args = Args {
        elf,
        bootloader: None,
        sd: None,
        sd_insert_at: None,
        pulls: Vec::new(),
        reinserts: Vec::new(),
        faults: Vec::new(),
        send: None,
        at: Vec::new(),
        at1: Vec::new(),
        seconds: None,
        vcd: None,
        png: None,
        report: None,
        eeprom: None,
        machine: None,
        endstop_mm: 3.0,
        echo: false,
        auto_confirm: false,
        pty: None,
        pty1: None,
        profile: None,
        cut: None,
        cut_delay: Duration::ZERO,
    };
    while let Some(a) = it.next() {
        let mut value = || it.next().ok_or(format!("{a} needs a value"));
        let time = |text: String| scenario::seconds(&text).map_err(|e| format!("{a}: {e}"));
        match a.as_str() {
            "--for" => args.seconds = Some(time(value()?)?),
            "--bootloader" => args.bootloader = Some(value()?.into()),
            "--sd" => args.sd = Some(value()?.into()),
            "--sd-insert-at" => args.sd_insert_at = Some(time(value()?)?),
            "--pull-card-at" => args.pulls.push(time(value()?)?),
            "--reinsert-at" => args.reinserts.push(time(value()?)?),
            "--card-fault" => args.faults.push(value()?.parse()?),
            "--send" => args.send = Some(value()?.into()),
            "--at" => args
                .at
                .push(value()?.parse().map_err(|e| format!("--at {e}"))?),
            "--at1" => args
                .at1
                .push(value()?.parse().map_err(|e| format!("--at1 {e}"))?),
            "--vcd" => args.vcd = Some(value()?.into()),
            "--png" => args.png = Some(value()?.into()),
            "--report" => args.report = Some(value()?.into()),
            "--eeprom" => args.eeprom = Some(value()?.into()),
            "--machine" => {
                let name = value()?;
                let m = Machine::parse(name.as_bytes())
                    .ok_or(format!("--machine {name}: no such machine"))?;
                args.machine = Some(m);
            }
            "--endstop-mm" => args.endstop_mm = value()?.parse().map_err(|_| "--endstop-mm MM")?,
            "--echo" => args.echo = true,
            "--pty" => {
                let link = it.next_if(|v| !v.starts_with("--")).map(PathBuf::from);
                args.pty = Some(link);
            }
            "--pty1" => {
                let link = it.next_if(|v| !v.starts_with("--")).map(PathBuf::from);
                args.pty1 = Some(link);
            }
            "--auto-confirm" => args.auto_confirm = true,
            "--power-cut-at" => args.cut = Some(Cut::At(time(value()?)?)),
            "--power-cut-on" => args.cut = Some(Cut::On(value()?)),
            "--power-cut-delay" => args.cut_delay = time(value()?)?,
            "--profile" => {
                args.profile = Some(value()?.parse().map_err(|_| "--profile N")?);
            }
            _ => return Err(format!("unknown option {a}")),
        }
    }
    // A plotter's picture needs no card (the machine may also come from
    // --eeprom: checked when drawn).
    let plotter = args.machine.is_some_and(|m| !m.is_string_art());
    let card_options = args.sd_insert_at.is_some()
        || (args.png.is_some() && !plotter && args.eeprom.is_none())
        || !args.pulls.is_empty()
        || !args.reinserts.is_empty()
        || !args.faults.is_empty();
    if card_options && args.sd.is_none() {
        return Err(
            "--sd-insert-at, --pull-card-at, --reinsert-at, --card-fault and --png need --sd"
                .into(),
        );
    }
    scenario::check_card_plan(args.sd_insert_at, &args.pulls, &args.reinserts)?;
    if args.cut_delay > Duration::ZERO && !matches!(args.cut, Some(Cut::On(_))) {
        return Err("--power-cut-delay needs --power-cut-on".into());
    }
    if args.elf.is_none() && args.bootloader.is_none() {
        return Err("missing ELF (or --bootloader HEX)".into());
    }
    if args.pty1.is_some() {
        args.pty.get_or_insert(None);
    }
    if args.bootloader.is_some() && args.pty.is_none() {
        return Err("--bootloader needs --pty: the bootloader talks over the serial port".into());
    }
    if args.auto_confirm && args.sd.is_none() {
        return Err("--auto-confirm needs --sd: the job comes from the card".into());
    }
    if args.profile.is_some() && args.bootloader.is_some() {
        return Err("--profile needs the ELF loaded as is (not with --bootloader)".into());
    }
    Ok(args)
}

impl Args {
    /// The simulated time of the last planned event.
    fn last_planned(&self) -> Option<Duration> {
        let times = self.at.iter().chain(&self.at1).map(|t| t.at);
        let faults = self.faults.iter().filter_map(FaultSpec::at);
        (times.chain(self.pulls.iter().copied()))
            .chain(self.reinserts.iter().copied())
            .chain(faults)
            .max()
    }
}

/// Send every line of `file` as a G-code sender would (next line after the
/// reply), then wait until motion is idle (`M400`).
fn stream(
    sim: &mut Sim,
    file: &Path,
    echo: bool,
    printed: &mut usize,
) -> Result<(), Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(file).map_err(|e| format!("{}: {e}", file.display()))?;
    if sim.run_until_uart_contains("reset:", Duration::from_millis(100)) != Outcome::Done {
        return Err("the firmware did not boot".into());
    }
    // A machine homing at power-on reads no line until it is done (as a
    // sender waits for Grbl's homing cycle).
    sim.run_for(Duration::from_millis(5));
    if sim.uart_text().contains("] homing") {
        sim.run_until(
            |s| s.uart_text().contains("homed") || s.uart_text().contains("homing failed"),
            Duration::from_secs(600),
        );
    }
    let lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    for (n, line) in lines.chain(std::iter::once("M400")).enumerate() {
        // Motion may have to finish first (M400, a full planner): be patient.
        match sim.send_line(line, Duration::from_secs(3600)) {
            Ok(Reply::Ok) => {}
            Ok(Reply::Error(e)) => eprintln!("taut-sim: line {}: {line}: {e}", n + 1),
            Err(e) => return Err(format!("line {}: {line}: no reply ({e:?})", n + 1).into()),
        }
        if echo {
            let out = sim.uart_bytes();
            std::io::stdout().write_all(&out[*printed..])?;
            *printed = out.len();
        }
    }
    Ok(())
}

/// Puts the card of `path` in the slot (at power-on or `--sd-insert-at`)
/// with its faults, pulls and re-insertions planned; returns its
/// `param.txt`.
fn put_card(sim: &mut Sim, path: &Path, args: &Args) -> Result<Option<Vec<u8>>, String> {
    let image = SdImage::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let param = image.read_file("param.txt");
    let mut planned = Vec::new();
    let mut card = SdCard::new(image);
    for spec in &args.faults {
        match spec.resolve(card.image())? {
            (None, fault) => card.inject(fault),
            (Some(at), fault) => planned.push((at, fault)),
        }
    }
    match args.sd_insert_at {
        Some(at) => sim.sd_insert_at(at, card),
        None => sim.insert_sd(card),
    }
    for &at in &args.pulls {
        sim.sd_remove_at(at);
    }
    for &at in &args.reinserts {
        sim.sd_reinsert_at(at);
    }
    for (at, fault) in planned {
        sim.sd_fault_at(at, fault);
    }
    Ok(param)
}

fn run(args: Args) -> Result<Ending, Box<dyn std::error::Error>> {
    let mut sim = match (&args.bootloader, &args.elf) {
        (Some(hex), app) => Sim::with_bootloader(hex, app.as_deref())?,
        (None, Some(elf)) => Sim::load(elf)?,
        (None, None) => unreachable!("parse asks for one"),
    };
    if args.profile.is_some() {
        sim.enable_profile();
    }
    if let Some(path) = args.eeprom.as_ref().filter(|p| p.exists()) {
        sim.set_eeprom(&std::fs::read(path)?);
    }
    // A cut may fall in the middle of an EEPROM write.
    sim.watch_eeprom();
    if let Some(m) = args.machine {
        let cfg = MachineConfig::defaults(m);
        sim.set_eeprom(&host::eeprom(
            &cfg,
            &Default::default(),
            &Default::default(),
        ));
    }
    // The machine the EEPROM holds: its channel names and switches.
    let eeprom = sim.eeprom();
    let cfg = host::settings(&eeprom).map_or(MachineConfig::STRING_ART, |(c, _)| c);
    sim.probe_machine(cfg.machine);
    let endstops = sim.fit_machine_endstops(&cfg, args.endstop_mm);
    let param = match &args.sd {
        Some(path) => put_card(&mut sim, path, &args)?,
        None => None,
    };
    for t in &args.at {
        sim.uart_send_at(t.at, &t.bytes);
    }
    for t in &args.at1 {
        sim.uart1_send_at(t.at, &t.bytes);
    }
    let wall = Instant::now();
    let mut printed = 0;
    if let Some(file) = &args.send {
        stream(&mut sim, file, args.echo, &mut printed)?;
    }
    let mut pty = match &args.pty {
        Some(link) => {
            let mut pty = Pty::open(link.as_deref())?;
            if args.bootloader.is_some() {
                pty.reset_on_open()?;
                pty.set_pace(Pace::BusyLink);
            }
            eprintln!(
                "taut-sim: serial port on {}{}",
                pty.path().display(),
                link.as_ref()
                    .map_or(String::new(), |l| format!(" (link {})", l.display()))
            );
            if let Some(link1) = &args.pty1 {
                let pty1 = Pty::open(link1.as_deref())?;
                eprintln!(
                    "taut-sim: UART1 (second console) on {}{}",
                    pty1.path().display(),
                    link1
                        .as_ref()
                        .map_or(String::new(), |l| format!(" (link {})", l.display()))
                );
                pty.serve_uart1(pty1);
            }
            stop_on_signals();
            Some(pty)
        }
        None => None,
    };
    let plan = plan(&args, sim.cycles());
    let mut session = Session::new(&mut sim, &plan);
    let mut bar = Bar::default();
    let ending = session.run(&plan, pty.as_mut(), &STOP, |sim, seen| {
        if args.echo {
            let text = &sim.uart_bytes()[printed..];
            let _ = bar.suspend(|| std::io::stdout().write_all(text));
            printed += text.len();
        }
        bar.show(seen);
    })?;
    bar.finish();
    let operator = std::mem::take(&mut session.operator);
    let print = session.print.clone();
    let wall_s = wall.elapsed().as_secs_f64();
    let cut = match ending {
        Ending::PowerCut { cycle } => Some(cycle),
        _ => None,
    };
    let (eeprom, torn) = match cut {
        Some(_) => sim.eeprom_after_cut(0xFF),
        None => (sim.eeprom(), None),
    };
    if let Some(path) = &args.eeprom {
        std::fs::write(path, eeprom)?;
    }
    if let Some(cycle) = cut {
        eprintln!(
            "taut-sim: power cut at cycle {cycle} ({:.6} s){}",
            cycle as f64 / FREQ_HZ as f64,
            torn.map_or(String::new(), |a| format!(
                " during the write of EEPROM byte {a}: left erased"
            ))
        );
    }
    if let Some(path) = &args.vcd {
        sim.write_vcd(path)?;
    }
    let mut picture = None;
    if let (Some(path), false) = (&args.png, cfg.machine.is_string_art()) {
        let origin = endstops.power_on_origin(&sim, &cfg);
        let p = picture::render_plot(&sim.vcd_signals(), &cfg, origin, path)?;
        eprintln!(
            "taut-sim: {}: {} steps, {} with the pen down, drawn over x {:.2}..{:.2}, y {:.2}..{:.2} mm",
            path.display(),
            p.steps,
            p.steps_down,
            p.min[0],
            p.max[0],
            p.min[1],
            p.max[1]
        );
        picture = Some(serde_json::to_value(&p)?);
    } else if let Some(path) = &args.png {
        let param = param.ok_or("--png: the card has no param.txt")?;
        let board = replay::board_from_param(&param).map_err(|e| format!("param.txt: {e}"))?;
        let s = picture::render_job(&sim.vcd_signals(), board, &MachineConfig::STRING_ART, path)?;
        eprintln!(
            "taut-sim: {}: {} holes, {} wraps, {} ring crossings outside a gap, {} moves with the drill down",
            path.display(),
            s.holes,
            s.wraps,
            s.crossings_outside_gaps,
            s.moves_while_plunged
        );
        picture = Some(serde_json::to_value(&s)?);
    }
    if let (Some(n), Some(profile), Some(elf)) = (args.profile, sim.profile(), &args.elf) {
        let by_function = profile.by_function(elf)?;
        let total: u64 = by_function.iter().map(|(c, _)| c).sum();
        eprintln!("taut-sim: cycles by function ({total} in all)");
        if std::env::var_os("TAUT_PROFILE_PCS").is_some() {
            for (pc, cycles) in profile.hottest(n) {
                eprintln!("{pc:#07x} {cycles:>12}");
            }
        }
        for (cycles, name) in by_function.iter().take(n) {
            let share = 100.0 * *cycles as f64 / total.max(1) as f64;
            eprintln!("{share:6.2} % {cycles:>12} {name}");
        }
    }
    let outcome = match &ending {
        Ending::Fault(o) => *o,
        _ => Outcome::Running,
    };
    if let Some(path) = &args.report {
        let mut report = serde_json::to_value(sim.report(outcome))?;
        let extra = json!({
            "ended": ending.kind(),
            "ending": ending.words(),
            "exit_status": ending.exit_code(),
            "power_cut": cut.map(|cycle| json!({
                "cycle": cycle,
                "at_s": cycle as f64 / FREQ_HZ as f64,
                "eeprom_byte_torn": torn,
            })),
            "wall_seconds": wall_s,
            "sim_mhz": sim.cycles() as f64 / wall_s / 1e6,
            "external_resets": sim.external_resets(),
            "job": {
                "state": operator.state,
                "progress": operator.progress,
                "finished": operator.finished,
                "green_presses": operator.presses,
                "resumes": operator.resumes,
                "picture": picture,
            },
            "print": {
                "file": print.opened,
                "started": print.running,
                "done": print.done,
            },
        });
        report
            .as_object_mut()
            .unwrap()
            .extend(extra.as_object().unwrap().clone());
        std::fs::write(path, serde_json::to_string_pretty(&report)?)?;
    }
    eprintln!(
        "taut-sim: {:.3} s of machine time in {:.2} s ({:.0} simulated MHz), ended: {}",
        sim.time_s(),
        wall_s,
        sim.cycles() as f64 / wall_s / 1e6,
        ending.words()
    );
    Ok(ending)
}

/// The run's limit and cut, in cycles since power-on, from the options
/// and where the machine stands (after `--send`'s stream).
fn plan(args: &Args, now: u64) -> Plan {
    let seconds = |d: Duration| cycles_in(d);
    let limit = match (args.seconds, args.send.is_some()) {
        (Some(d), true) => Some(now + seconds(d)),
        (Some(d), false) => Some(seconds(d)),
        (None, true) => Some(now),
        (None, false) if args.pty.is_some() || args.auto_confirm => None,
        (None, false) => Some(seconds(Duration::from_secs(5))),
    };
    // Without --for, the run also covers every planned event.
    let limit = match (args.seconds, args.last_planned()) {
        (None, Some(last)) => limit.map(|l| l.max(seconds(last + Duration::from_secs(1)))),
        _ => limit,
    };
    let cut = match &args.cut {
        Some(Cut::At(at)) => Some(session::Cut::At(seconds(*at))),
        Some(Cut::On(text)) => Some(session::Cut::On {
            text: text.clone(),
            delay: seconds(args.cut_delay),
        }),
        None => None,
    };
    Plan {
        limit,
        cut,
        auto_confirm: args.auto_confirm,
        file_sent: args.send.is_some(),
    }
}

/// The job's progress lines (`drill 3/24`, `wind 10/30`) as a bar per
/// phase, with the job's state as its message. Drawn only on a terminal.
#[derive(Default)]
struct Bar {
    phase: Option<(String, ProgressBar)>,
}

impl Bar {
    fn show(&mut self, seen: &[Seen]) {
        for s in seen {
            match s {
                Seen::Progress(phase, done, total) => {
                    if self.phase.as_ref().is_none_or(|(p, _)| p != phase) {
                        self.finish();
                        let style = ProgressStyle::with_template(
                            "{prefix:>5} [{bar:40}] {pos}/{len} {msg} ({elapsed} wall, eta {eta})",
                        )
                        .expect("template")
                        .progress_chars("=> ");
                        let bar = ProgressBar::new(u64::from(*total))
                            .with_style(style)
                            .with_prefix(phase.clone());
                        self.phase = Some((phase.clone(), bar));
                    }
                    if let Some((_, bar)) = &self.phase {
                        bar.set_position(u64::from(*done));
                    }
                }
                Seen::State(state) => {
                    if let Some((_, bar)) = &self.phase {
                        bar.set_message(state.clone());
                    }
                }
                _ => {}
            }
        }
    }

    fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        match &self.phase {
            Some((_, bar)) => bar.suspend(f),
            None => f(),
        }
    }

    fn finish(&mut self) {
        if let Some((_, bar)) = self.phase.take() {
            bar.finish();
        }
    }
}

/// SIGINT or SIGTERM came: the run ends, its files are written.
static STOP: AtomicBool = AtomicBool::new(false);

extern "C" fn on_signal(_: libc::c_int) {
    STOP.store(true, Ordering::Relaxed);
}

fn stop_on_signals() {
    // SAFETY: the handler only stores to an atomic.
    unsafe {
        libc::signal(libc::SIGINT, on_signal as *const () as libc::sighandler_t);
        libc::signal(libc::SIGTERM, on_signal as *const () as libc::sighandler_t);
    }
}

fn main() -> ExitCode {
    if std::env::args().any(|a| a == "--help" || a == "-h") {
        println!("{USAGE}");
        return ExitCode::SUCCESS;
    }
    let args = match parse(std::env::args().skip(1)) {
        Ok(a) => a,
        Err(e) => {
            eprintln!("taut-sim: {e}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    match run(args) {
        Ok(ending) => ExitCode::from(ending.exit_code()),
        Err(e) => {
            eprintln!("taut-sim: {e}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(line: &str) -> Result<Args, String> {
        parse(line.split(' ').map(String::from))
    }

    /// The usage names every option this file matches on, and only those.
    #[test]
    fn usage_names_every_option() {
        let is_option = |w: &str| {
            w.len() > 2
                && w.starts_with("--")
                && w.chars().all(|c| c.is_ascii_lowercase() || c == '-')
        };
        let known: Vec<&str> = include_str!("taut-sim.rs")
            .split('"')
            .filter(|w| is_option(w))
            .collect();
        assert!(known.len() > 10, "{known:?}");
        for option in &known {
            assert!(USAGE.contains(option), "{option} missing from the usage");
            let e = args(&format!("fw.elf {option} 1"))
                .err()
                .unwrap_or_default();
            let unknown = e == format!("unknown option {option}");
            assert!(!unknown || *option == "--help", "{option}: {e}");
        }
        let named = USAGE.split(|c: char| c.is_whitespace() || "[],".contains(c));
        for option in named.filter(|w| is_option(w)) {
            assert!(known.contains(&option), "{option} in the usage only");
        }
    }

    #[test]
    fn a_fault_scenario_parses_whole() {
        let a = args(
            "fw.elf --sd card --pull-card-at 2 --reinsert-at 4.5 --pull-card-at 6 \
             --card-fault crc-once:poradi.txt --card-fault crc-once-at:3 \
             --at 1:? --at 2.5:\\x18 --at1 3:G0\\x20X5\\n --for 8",
        )
        .unwrap();
        assert_eq!(a.pulls, [2.0, 6.0].map(Duration::from_secs_f64));
        assert_eq!(a.reinserts, [Duration::from_secs_f64(4.5)]);
        assert_eq!(a.faults.len(), 2);
        assert_eq!(a.at[1].bytes, [0x18]);
        assert_eq!(a.at1[0].bytes, b"G0 X5\n");
        assert_eq!(a.seconds, Some(Duration::from_secs(8)));
        assert_eq!(a.last_planned(), Some(Duration::from_secs(6)));
    }

    /// A cut's time, as written, becomes one exact cycle: whole seconds
    /// and any decimals alike (a float compared against the simulated
    /// clock once missed 40 and 45).
    #[test]
    fn cut_times_are_exact_cycles() {
        let cut = |line: &str| plan(&args(line).unwrap(), 0).cut;
        for (text, cycle) in [
            ("40", 640_000_000),
            ("45", 720_000_000),
            ("0.1", 1_600_000),
            ("2.5", 40_000_000),
            ("0.25", 4_000_000),
        ] {
            assert_eq!(
                cut(&format!("fw.elf --power-cut-at {text}")),
                Some(session::Cut::At(cycle)),
                "{text}"
            );
        }
        assert_eq!(
            cut("fw.elf --power-cut-on x --power-cut-delay 7200"),
            Some(session::Cut::On {
                text: "x".into(),
                delay: 115_200_000_000
            })
        );
        let p = plan(&args("fw.elf --power-cut-at 45").unwrap(), 0);
        assert_eq!(
            p.limit,
            Some(80_000_000),
            "the plain 5 s: the cut outlasts it"
        );
        let p = plan(&args("fw.elf --sd c --auto-confirm").unwrap(), 0);
        assert_eq!(p.limit, None, "--auto-confirm runs the job to its end");
    }

    #[test]
    fn card_options_need_a_card_and_a_sensible_plan() {
        for line in [
            "fw.elf --pull-card-at 2",
            "fw.elf --card-fault bad-block:3",
            "fw.elf --sd c --reinsert-at 2",
            "fw.elf --sd c --pull-card-at 2 --pull-card-at 3",
            "fw.elf --sd c --card-fault crc-twice:3",
            "fw.elf --at 2",
            "fw.elf --for -1",
            "fw.elf --power-cut-at 3 --power-cut-delay 1",
            "fw.elf --power-cut-on",
        ] {
            assert!(args(line).is_err(), "{line}");
        }
    }
}
