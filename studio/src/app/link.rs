//! The serial link to the machine (`serialport`, 115 200 8N1 raw): a Mega
//! on USB or the simulator's pseudo-terminal. A reader thread hands every
//! line to the hub; a read or write error is a lost link, shown at once.
use serde::Serialize;
use serialport::SerialPort;
use std::io::Read;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

pub struct Link {
    pub name: String,
    port: Mutex<Box<dyn SerialPort>>,
    closed: Arc<AtomicBool>,
}

/// A port the page can offer.
#[derive(Serialize)]
pub struct PortInfo {
    pub path: String,
    pub what: String,
}

/// The serial ports of the system, USB ones first (a Mega is
/// `/dev/ttyACM0`), and the simulator's terminal if there is one.
pub fn ports(sim: Option<&str>) -> Vec<PortInfo> {
    let mut out: Vec<PortInfo> = sim
        .map(|p| PortInfo {
            path: p.to_string(),
            what: "simulated Mega (release image)".into(),
        })
        .into_iter()
        .collect();
    // serialport scans /sys/class/tty (it panics where that is missing).
    let found = std::panic::catch_unwind(serialport::available_ports).unwrap_or(Ok(Vec::new()));
    let mut system: Vec<PortInfo> = found
        .unwrap_or_default()
        .into_iter()
        .map(|p| PortInfo {
            what: match p.port_type {
                serialport::SerialPortType::UsbPort(u) => {
                    format!("USB {}", u.product.unwrap_or_default())
                        .trim()
                        .to_string()
                }
                serialport::SerialPortType::BluetoothPort => "Bluetooth".into(),
                _ => "serial".into(),
            },
            path: p.port_name,
        })
        .collect();
    system.sort_by_key(|p| (!p.what.starts_with("USB"), p.path.clone()));
    out.extend(system);
    out
}

/// What the reader thread hands each line and a lost link to (the hub).
pub trait Listener: Send + Sync + 'static {
    fn on_line(&self, line: &str);
    fn lost_now(&self, why: &str);
}

impl Link {
    /// Opens `path` and starts reading it into `hub`.
    pub fn open(path: &str, hub: Arc<impl Listener>) -> Result<Arc<Link>, String> {
        let port = serialport::new(path, 115_200)
            .timeout(Duration::from_millis(100))
            .open()
            .map_err(|e| format!("{path}: {e}"))?;
        let mut reader = port.try_clone().map_err(|e| format!("{path}: {e}"))?;
        let closed = Arc::new(AtomicBool::new(false));
        let link = Arc::new(Link {
            name: path.to_string(),
            port: Mutex::new(port),
            closed: closed.clone(),
        });
        let name = path.to_string();
        std::thread::Builder::new()
            .name(format!("serial {name}"))
            .spawn(move || {
                let mut line = Vec::new();
                let mut buf = [0u8; 256];
                while !closed.load(Ordering::Relaxed) {
                    match reader.read(&mut buf) {
                        Ok(0) => {
                            hub.lost_now("the port closed");
                            break;
                        }
                        Ok(n) => {
                            for &b in &buf[..n] {
                                match b {
                                    b'\n' => {
                                        let text = String::from_utf8_lossy(&line);
                                        let text = text.trim_end_matches('\r');
                                        if !closed.load(Ordering::Relaxed) && !text.is_empty() {
                                            hub.on_line(text);
                                        }
                                        line.clear();
                                    }
                                    _ => line.push(b),
                                }
                            }
                        }
                        Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
                        Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                        Err(e) => {
                            if !closed.load(Ordering::Relaxed) {
                                hub.lost_now(&e.to_string());
                            }
                            break;
                        }
                    }
                }
            })
            .map_err(|e| e.to_string())?;
        Ok(link)
    }

    pub fn write(&self, bytes: &[u8]) -> Result<(), String> {
        let mut port = self.port.lock().unwrap_or_else(|e| e.into_inner());
        std::io::Write::write_all(&mut *port, bytes).map_err(|e| format!("{}: {e}", self.name))
    }

    /// Stops the reader (it ends within its 100 ms read timeout).
    pub fn close(&self) {
        self.closed.store(true, Ordering::Relaxed);
    }
}
