//! The simulated Mega the app can drive without hardware (`taut studio
//! --sim ELF`, which `cargo xtask studio` runs): the release image in
//! simavr, powered on as a machine, its serial port a pseudo-terminal that
//! the app opens like any port, in real time. Being in the app's own
//! process, the page can also do what a person at the machine does: put a
//! card in the slot and press the machine's buttons. Every pin is probed,
//! and the trace (VCD) is written when the app ends.
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
    Stop(mpsc::Sender<Result<Ended, String>>),
}

/// What the run left: where the drawing motors stood at power-on in the
/// machine's coordinates (steps), for reading the trace.
#[derive(Clone, Debug)]
pub struct Ended {
    pub origin: [i32; 2],
    pub seconds: f64,
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
    let mut sim = match Sim::load(elf) {
        Ok(sim) => sim,
        Err(e) => {
            let _ = ready.send(Err(format!("{}: {e}", elf.display())));
            return;
        }
    };
    let cfg = MachineConfig::defaults(machine);
    let eeprom = host::eeprom(&cfg, &Default::default(), &Default::default());
    sim.set_eeprom(&eeprom);
    sim.probe_machine(machine);
    let endstops = sim.fit_machine_endstops(&cfg, 3.0);
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
        seconds: sim.time_s(),
    });
    drop(pty);
    if let Some(tx) = stop {
        let _ = tx.send(ended);
    }
}
