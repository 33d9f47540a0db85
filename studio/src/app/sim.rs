//! The simulated Mega the app can drive without hardware (`taut studio
//! --sim ELF`, which `cargo xtask studio` runs): the release image in
//! simavr, powered on as a machine, its serial port a pseudo-terminal that
//! the app opens like any port, in real time. Being in the app's own
//! process, the page can also do what a person at the machine does: put a
//! card in the slot, press the machine's buttons, and cut the power (only
//! the EEPROM, as the cut leaves it, and the card in the slot survive;
//! the board starts again at once, behind the same terminal). Every pin
//! is probed, and the trace (VCD) is written when the app ends; a power
//! cut writes the trace up to it beside it (`studio.vcd`: `studio-cut1.vcd`
//! …).
//!
//! The simulator (simavr, in C) is built into `taut` only with the `sim`
//! feature, which `cargo xtask studio` and the HIL tests turn on: a maker's
//! `taut` stays pure Rust, and `--sim` then says how to get it.

use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;
use taut_logic::machine::Machine;
use taut_logic::pinmap::Button;

/// How long a short press is held (a long press: 2.5 s).
const PRESS: Duration = Duration::from_millis(150);
const LONG_PRESS: Duration = Duration::from_millis(2500);

#[cfg_attr(not(feature = "sim"), allow(dead_code))]
enum Command {
    Press(Button, Duration),
    /// A folder holding the card's files (imaged, then removed).
    Card(PathBuf),
    PowerCut(mpsc::Sender<Result<u32, String>>),
    Stop(mpsc::Sender<Result<Ended, String>>),
}

/// What the run left: where the drawing motors stood at power-on in the
/// machine's coordinates (steps), for reading the trace.
#[derive(Clone, Debug)]
pub struct Ended {
    pub origin: [i32; 2],
    /// Machine time over every power-on, s.
    pub seconds: f64,
    /// The traces up to each power cut, in order (the last power-on's is
    /// the VCD file asked for).
    pub cut_traces: Vec<PathBuf>,
}

pub struct SimHost {
    /// The terminal's path (a link in a private temporary folder).
    pub tty: PathBuf,
    pub machine: Machine,
    commands: mpsc::Sender<Command>,
}

impl SimHost {
    /// Loads `elf`, powers it on as `machine` and serves its port.
    pub fn start(elf: &Path, machine: Machine, vcd: Option<PathBuf>) -> Result<SimHost, String> {
        let dir = std::env::temp_dir().join(format!("taut-studio-{}", std::process::id()));
        std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let tty = dir.join(format!("tty-{}", unique()));
        let (commands, inbox) = mpsc::channel();
        let (ready, started) = mpsc::channel();
        let (elf, link) = (elf.to_path_buf(), tty.clone());
        std::thread::Builder::new()
            .name("simulator".into())
            .spawn(move || serve(&elf, machine, &link, vcd, &inbox, &ready))
            .map_err(|e| e.to_string())?;
        started
            .recv()
            .map_err(|_| "the simulator thread ended".to_string())??;
        Ok(SimHost {
            tty,
            machine,
            commands,
        })
    }

    /// Presses a button of the machine (`long`: held 2.5 s).
    pub fn press(&self, button: Button, long: bool) -> Result<(), String> {
        let hold = if long { LONG_PRESS } else { PRESS };
        self.send(Command::Press(button, hold))
    }

    /// Puts a card holding `files` in the slot (replacing any there).
    pub fn insert_card(&self, files: &[(&str, &[u8])]) -> Result<(), String> {
        let dir = std::env::temp_dir().join(format!(
            "taut-studio-{}/card-{}",
            std::process::id(),
            unique()
        ));
        std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
        for (name, bytes) in files {
            std::fs::write(dir.join(name), bytes).map_err(|e| e.to_string())?;
        }
        self.send(Command::Card(dir))
    }

    /// Cuts the power and switches it on again: what the EEPROM holds (a
    /// byte being written is left erased) and the card in the slot
    /// survive. Returns how many cuts there have been.
    pub fn power_cut(&self) -> Result<u32, String> {
        let (tx, rx) = mpsc::channel();
        self.send(Command::PowerCut(tx))?;
        rx.recv().map_err(|_| "the simulator ended".to_string())?
    }

    /// Ends the simulation; the trace is written (if asked for).
    pub fn stop(&self) -> Result<Ended, String> {
        let (tx, rx) = mpsc::channel();
        self.send(Command::Stop(tx))?;
        rx.recv().map_err(|_| "the simulator ended".to_string())?
    }

    fn send(&self, c: Command) -> Result<(), String> {
        self.commands
            .send(c)
            .map_err(|_| "the simulator has ended".to_string())
    }
}

fn unique() -> u64 {
    static N: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    N.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// The trace up to the `n`-th power cut: `studio.vcd` → `studio-cut1.vcd`.
#[cfg_attr(not(feature = "sim"), allow(dead_code))]
fn cut_trace(vcd: &Path, n: usize) -> PathBuf {
    let stem = vcd.file_stem().unwrap_or_default().to_string_lossy();
    vcd.with_file_name(format!("{stem}-cut{n}.vcd"))
}

/// Without the simulator built in: says how to get it.
#[cfg(not(feature = "sim"))]
fn serve(
    _: &Path,
    _: Machine,
    _: &Path,
    _: Option<PathBuf>,
    _: &mpsc::Receiver<Command>,
    ready: &mpsc::Sender<Result<(), String>>,
) {
    let _ = ready.send(Err(
        "this taut was built without the simulator: run `cargo xtask studio`, \
         or build taut with `--features sim`"
            .into(),
    ));
}

/// The simulator's thread: the machine in real time until told to stop.
#[cfg(feature = "sim")]
fn serve(
    elf: &Path,
    machine: Machine,
    link: &Path,
    vcd: Option<PathBuf>,
    inbox: &mpsc::Receiver<Command>,
    ready: &mpsc::Sender<Result<(), String>>,
) {
    use taut_logic::config::MachineConfig;
    use taut_logic::settings::eeprom::host;
    use taut_simavr::{pty::Pty, sdcard::SdImage, sdimage::FatChoice, Sim};
    let cfg = MachineConfig::defaults(machine);
    // A board powered on with `eeprom`: every pin probed, the endstops
    // where the machine's are.
    let power_on = |eeprom: &[u8]| {
        let mut sim = Sim::load(elf).map_err(|e| format!("{}: {e}", elf.display()))?;
        sim.set_eeprom(eeprom);
        sim.watch_eeprom();
        sim.probe_machine(machine);
        let endstops = sim.fit_machine_endstops(&cfg, 3.0);
        Ok::<_, String>((sim, endstops))
    };
    let (mut sim, mut endstops) = match power_on(&host::eeprom(
        &cfg,
        &Default::default(),
        &Default::default(),
    )) {
        Ok(s) => s,
        Err(e) => {
            let _ = ready.send(Err(e));
            return;
        }
    };
    let mut pty = match Pty::open(Some(link)) {
        Ok(p) => p,
        Err(e) => {
            let _ = ready.send(Err(format!("pseudo-terminal: {e}")));
            return;
        }
    };
    let _ = ready.send(Ok(()));
    // Releases due: simulated second, pin.
    let mut releases: Vec<(f64, u8)> = Vec::new();
    let mut cut_traces = Vec::new();
    let mut seconds_before = 0.0;
    let mut cuts = 0u32;
    let stop = loop {
        match inbox.try_recv() {
            Ok(Command::Press(b, hold)) => {
                sim.press(b.pin());
                releases.push((sim.time_s() + hold.as_secs_f64(), b.pin()));
            }
            Ok(Command::Card(dir)) => {
                match SdImage::from_dir(&dir, FatChoice::Auto) {
                    Ok(image) => sim.insert_sd(image),
                    Err(e) => eprintln!("taut studio: simulator: the card image: {e}"),
                }
                let _ = std::fs::remove_dir_all(&dir);
            }
            Ok(Command::PowerCut(tx)) => {
                let (eeprom, _) = sim.eeprom_after_cut(0xFF);
                let card = sim.remove_sd();
                if let Some(path) = &vcd {
                    let cut = cut_trace(path, cuts as usize + 1);
                    if let Err(e) = sim.write_vcd(&cut) {
                        eprintln!("taut studio: simulator: {}: {e}", cut.display());
                    }
                    cut_traces.push(cut);
                }
                seconds_before += sim.time_s();
                match power_on(&eeprom) {
                    Ok((next, e)) => (sim, endstops) = (next, e),
                    Err(e) => {
                        let _ = tx.send(Err(e));
                        break None;
                    }
                }
                if let Some(card) = card {
                    sim.insert_sd(card);
                }
                // Buttons held through the cut are let go.
                releases.clear();
                pty.board_replaced();
                cuts += 1;
                let _ = tx.send(Ok(cuts));
            }
            Ok(Command::Stop(tx)) => break Some(tx),
            Err(mpsc::TryRecvError::Empty) => {}
            Err(mpsc::TryRecvError::Disconnected) => break None,
        }
        let now = sim.time_s();
        releases.retain(|&(at, pin)| {
            if at <= now {
                sim.release(pin);
            }
            at > now
        });
        match pty.serve(&mut sim, Duration::from_millis(5)) {
            Ok(outcome) if outcome.is_fatal() => {
                // The port goes away with it: the page shows the link lost.
                eprintln!("taut studio: simulator: firmware fault: {outcome:?}");
                break None;
            }
            Ok(_) => {}
            Err(e) => {
                eprintln!("taut studio: simulator: {e}");
                break None;
            }
        }
    };
    let result = match &vcd {
        Some(path) => sim
            .write_vcd(path)
            .map_err(|e| format!("{}: {e}", path.display())),
        None => Ok(()),
    };
    let ended = result.map(|()| Ended {
        origin: endstops.power_on_origin(&sim, &cfg),
        seconds: seconds_before + sim.time_s(),
        cut_traces,
    });
    drop(pty);
    if let Some(tx) = stop {
        let _ = tx.send(ended);
    }
}
