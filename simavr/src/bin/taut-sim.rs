//! `taut-sim ELF [options]`: run a firmware image on the simulated machine
//! with every RAMPS pin probed under its fixed VCD name, then write the
//! trace and a JSON report. `cargo xtask sim` calls it with the release ELF.

use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};
use taut_logic::axis::Axis;
use taut_logic::config::MachineConfig;
use taut_logic::pinmap::{self, Button};
use taut_simavr::operator::{Operator, Seen};
use taut_simavr::sdcard::SdImage;
use taut_simavr::{picture, replay};
use taut_simavr::{Outcome, Reply, Sim};

const USAGE: &str = "\
usage: taut-sim ELF [--sd DIR_OR_IMAGE [--sd-insert-at SECONDS]] [--auto-confirm]
                   [--send FILE] [--for SECONDS] [--vcd PATH] [--png PATH]
                   [--report PATH] [--echo]
  --sd PATH       put a virtual SD card in the slot: an image file, or a
                  folder, imaged on the fly (FAT16 or FAT32 by size)
  --sd-insert-at SECONDS
                  insert that card later instead of at power-on
  --send FILE     stream FILE's lines to the serial console, each after the
                  previous one's ok/error, then run until motion is idle
  --for SECONDS   simulated time to run (default 5; with --send: extra time
                  after motion is idle, default 0)
  --vcd PATH      write a VCD trace of every probed pin
  --png PATH      draw the string-art job from the step pulses alone (the
                  board from the card's param.txt; needs --sd)
  --report PATH   write a JSON report (cycles, time, outcome, UART, pin figures)
  --auto-confirm  press the green button whenever the job asks for it, and
                  run until the job is done (or --for SECONDS, default 7200)
  --echo          print the firmware's serial output as it runs";

struct Args {
    elf: PathBuf,
    sd: Option<PathBuf>,
    sd_insert_at: Option<f64>,
    send: Option<PathBuf>,
    seconds: Option<f64>,
    vcd: Option<PathBuf>,
    png: Option<PathBuf>,
    report: Option<PathBuf>,
    echo: bool,
    auto_confirm: bool,
}

fn parse(mut it: impl Iterator<Item = String>) -> Result<Args, String> {
    let elf = it.next().ok_or("missing ELF")?.into();
    let mut args = Args {
        elf,
        sd: None,
        sd_insert_at: None,
        send: None,
        seconds: None,
        vcd: None,
        png: None,
        report: None,
        echo: false,
        auto_confirm: false,
    };
    while let Some(a) = it.next() {
        let mut value = || it.next().ok_or(format!("{a} needs a value"));
        match a.as_str() {
            "--for" => args.seconds = Some(value()?.parse().map_err(|e| format!("--for: {e}"))?),
            "--sd" => args.sd = Some(value()?.into()),
            "--sd-insert-at" => {
                args.sd_insert_at = Some(
                    value()?
                        .parse()
                        .map_err(|e| format!("--sd-insert-at: {e}"))?,
                )
            }
            "--send" => args.send = Some(value()?.into()),
            "--vcd" => args.vcd = Some(value()?.into()),
            "--png" => args.png = Some(value()?.into()),
            "--report" => args.report = Some(value()?.into()),
            "--echo" => args.echo = true,
            "--auto-confirm" => args.auto_confirm = true,
            _ => return Err(format!("unknown option {a}")),
        }
    }
    if (args.sd_insert_at.is_some() || args.png.is_some()) && args.sd.is_none() {
        return Err("--sd-insert-at and --png need --sd".into());
    }
    Ok(args)
}

/// Probes with the documented signal names: `<axis>_step|dir|en`,
/// `btn_<button>`, `led`.
fn probe_machine(sim: &mut Sim) {
    for axis in [Axis::Base, Axis::Radial, Axis::Drill] {
        let d = pinmap::driver(axis);
        sim.probe_step_dir(axis.name(), d.step, d.dir, true);
        sim.probe(d.enable, &format!("{}_en", axis.name()));
    }
    for b in Button::ALL {
        sim.probe(b.pin(), &format!("btn_{}", b.name()));
    }
    sim.probe(pinmap::STATUS_LED, "led");
}

/// Send every line of `file` as a G-code sender would (next line after the
/// reply), then wait until motion is idle (`M400`).
fn stream(
    sim: &mut Sim,
    file: &std::path::Path,
    echo: bool,
    printed: &mut usize,
) -> Result<(), Box<dyn std::error::Error>> {
    let text = std::fs::read_to_string(file).map_err(|e| format!("{}: {e}", file.display()))?;
    if sim.run_until_uart_contains("reset:", Duration::from_millis(100)) != Outcome::Done {
        return Err("the firmware did not boot".into());
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

fn run(args: Args) -> Result<Outcome, Box<dyn std::error::Error>> {
    let mut sim = Sim::load(&args.elf)?;
    probe_machine(&mut sim);
    let mut param = None;
    if let Some(path) = &args.sd {
        let card = SdImage::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
        param = card.read_file("param.txt");
        match args.sd_insert_at {
            Some(s) => sim.sd_insert_at(Duration::from_secs_f64(s), card),
            None => sim.insert_sd(card),
        }
    }
    let wall = Instant::now();
    let mut printed = 0;
    if let Some(file) = &args.send {
        stream(&mut sim, file, args.echo, &mut printed)?;
    }
    let default = match (args.auto_confirm, args.send.is_some()) {
        (true, _) => 7200.0,
        (false, true) => 0.0,
        (false, false) => 5.0,
    };
    let mut operator = if args.auto_confirm {
        Operator::confirming()
    } else {
        Operator::default()
    };
    let mut bar = Bar::default();
    let total = Duration::from_secs_f64(args.seconds.unwrap_or(default));
    let slice = Duration::from_millis(10);
    let mut outcome = Outcome::Running;
    let mut elapsed = Duration::ZERO;
    while elapsed < total {
        let step = slice.min(total - elapsed);
        outcome = sim.run_for(step);
        elapsed += step;
        if args.echo {
            let text = &sim.uart_bytes()[printed..];
            bar.suspend(|| std::io::stdout().write_all(text))?;
            printed += text.len();
        }
        if outcome != Outcome::Running {
            break;
        }
        bar.show(&operator.step(&mut sim));
        if args.auto_confirm && operator.finished {
            break;
        }
    }
    bar.finish();
    let wall_s = wall.elapsed().as_secs_f64();
    if let Some(path) = &args.vcd {
        sim.write_vcd(path)?;
    }
    let mut picture = None;
    if let Some(path) = &args.png {
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
    if let Some(path) = &args.report {
        let mut report = serde_json::to_value(sim.report(outcome))?;
        let extra = json!({
            "wall_seconds": wall_s,
            "sim_mhz": sim.cycles() as f64 / wall_s / 1e6,
            "job": {
                "state": operator.state,
                "finished": operator.finished,
                "green_presses": operator.presses,
                "picture": picture,
            },
        });
        report
            .as_object_mut()
            .unwrap()
            .extend(extra.as_object().unwrap().clone());
        std::fs::write(path, serde_json::to_string_pretty(&report)?)?;
    }
    eprintln!(
        "taut-sim: {:.3} s of machine time in {:.2} s ({:.0} simulated MHz), ended: {:?}",
        sim.time_s(),
        wall_s,
        sim.cycles() as f64 / wall_s / 1e6,
        outcome
    );
    Ok(outcome)
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
        Ok(o) if !o.is_fatal() => ExitCode::SUCCESS,
        Ok(_) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("taut-sim: {e}");
            ExitCode::FAILURE
        }
    }
}
