//! `taut studio`: the web app a maker drives every machine from. One
//! binary serves the page (its files embedded, [`web`]) and the HTTP API
//! the page and scripts use ([`api`], documented in `docs/studio.md`):
//! the host tools as library calls ([`tools`]), the serial link to the
//! machine ([`link`]) with its console, status and events ([`hub`]), the
//! G-code run over `taut send`'s stream ([`run`]), and, with `--sim`, the
//! simulated Mega in the same process ([`sim`]).
//!
//! Safety: it listens on 127.0.0.1 unless told otherwise; on any other
//! address every request needs the token printed at start. One client
//! (a page, or a script) controls the machine at a time; the others
//! watch until they take over.

mod api;
mod hub;
mod link;
mod run;
pub mod sim;
pub mod tools;
mod web;
mod words;

use crate::args::AnyMachine;
pub use api::UPLOAD_LIMIT;
use hub::Hub;
use serde_json::json;
use sim::{Ended, SimHost};
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;
use taut_logic::machine::Machine;

/// The web app: open a picture, SVG or G-code, preview, connect, send
///
/// Vectorise a picture or make a string-art card, see the toolpath, connect
/// to the machine, use its console and buttons, send, pause, resume and
/// stop. Prints its URL and runs until Ctrl-C. On an address other than
/// 127.0.0.1 every request needs the token (printed, or --token T).
#[derive(clap::Args, Debug)]
#[command(after_help = "\
Examples:
  taut studio --serial /dev/ttyACM0             (a Mega on USB)
  cargo xtask studio --machine flatbed          (the simulated Mega)
  taut studio --sim firmware/target/avr-none/release/taut.elf --machine drum
                                                (a taut built with --features sim)")]
pub struct Cli {
    /// The HTTP port (0: any free one)
    #[arg(long, default_value_t = 8080)]
    pub port: u16,
    /// The address to listen on (127.0.0.1: this computer only)
    #[arg(long, default_value = "127.0.0.1", value_name = "ADDR")]
    pub bind: IpAddr,
    /// The token every request must carry (at least 8 characters) [default: made up when --bind is not 127.0.0.1]
    #[arg(long, value_name = "T")]
    pub token: Option<String>,
    /// Connect to this serial port at start (/dev/ttyACM0: a Mega on USB)
    #[arg(long, value_name = "PATH")]
    pub serial: Option<String>,
    /// Run this firmware image in the simulator and connect to it (needs the `sim` feature)
    #[arg(long, value_name = "ELF")]
    pub sim: Option<PathBuf>,
    /// The simulated board's machine; before `$$` is read, whose figures an ETA takes
    #[arg(long, value_enum, default_value = "flatbed")]
    pub machine: AnyMachine,
    /// Write the simulator's trace to this file when the app ends
    #[arg(long, value_name = "FILE", requires = "sim")]
    pub vcd: Option<PathBuf>,
}

/// What `taut studio` was told.
#[derive(Clone, Debug)]
pub struct Options {
    pub bind: IpAddr,
    /// 0: any free port.
    pub port: u16,
    pub token: Option<String>,
    pub serial: Option<String>,
    pub sim: Option<PathBuf>,
    pub machine: Machine,
    pub vcd: Option<PathBuf>,
    /// Connect at start: to `serial`, else to the simulator.
    pub connect: bool,
}

impl Default for Options {
    fn default() -> Options {
        Options {
            bind: IpAddr::V4(Ipv4Addr::LOCALHOST),
            port: 8080,
            token: None,
            serial: None,
            sim: None,
            machine: Machine::Flatbed,
            vcd: None,
            connect: false,
        }
    }
}

/// An error of a request: its HTTP status and what to tell the user.
#[derive(Debug)]
pub struct Bad {
    pub status: u16,
    pub message: String,
}

impl Bad {
    pub fn input(message: String) -> Bad {
        Bad {
            status: 400,
            message,
        }
    }

    pub fn conflict(message: impl Into<String>) -> Bad {
        Bad {
            status: 409,
            message: message.into(),
        }
    }
}

/// The app's state, shared by every request.
pub struct Studio {
    hub: Arc<Hub>,
    token: Option<String>,
    sim: Option<Arc<SimHost>>,
    /// The machine whose figures an ETA takes before `$$` was read.
    machine: Machine,
}

/// `taut studio …` from the command line.
pub fn run(cli: Cli) -> Result<(), String> {
    if let (Some(elf), Some(vcd)) = (&cli.sim, &cli.vcd) {
        crate::output::refuse_overwriting(&[elf.as_path()], &[vcd.as_path()])?;
    }
    let o = Options {
        bind: cli.bind,
        port: cli.port,
        token: cli.token,
        serial: cli.serial,
        sim: cli.sim,
        machine: cli.machine.into(),
        vcd: cli.vcd,
        connect: true,
    };
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .map_err(|e| e.to_string())?;
    runtime.block_on(async {
        let started = start(o).await?;
        println!("taut studio: {}", started.url);
        if started.token_shown {
            println!("taut studio: every request needs the token: it is in the address above");
        }
        println!("taut studio: Ctrl-C ends it");
        let ended = started.serve_until(interrupted()).await?;
        if let Some(e) = ended {
            eprintln!(
                "taut studio: the simulator ran {:.1} s of machine time",
                e.seconds
            );
        }
        Ok::<(), String>(())
    })
}

/// Ctrl-C (SIGINT) or SIGTERM.
async fn interrupted() {
    let mut term = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()).ok();
    let term = async {
        match term.as_mut() {
            Some(t) => {
                t.recv().await;
            }
            None => std::future::pending().await,
        }
    };
    tokio::select! {
        _ = tokio::signal::ctrl_c() => {}
        _ = term => {}
    }
}

/// A studio listening, not yet serving.
pub struct Started {
    pub url: String,
    pub addr: SocketAddr,
    token_shown: bool,
    listener: tokio::net::TcpListener,
    app: Arc<Studio>,
    poller: tokio::task::JoinHandle<()>,
}

/// Binds, starts the simulator if asked, connects if asked.
pub async fn start(o: Options) -> Result<Started, String> {
    let token = token_for(o.bind, o.token.clone())?;
    let listener = tokio::net::TcpListener::bind((o.bind, o.port))
        .await
        .map_err(|e| format!("{}:{}: {e}", o.bind, o.port))?;
    let addr = listener.local_addr().map_err(|e| e.to_string())?;
    let sim = match &o.sim {
        Some(elf) => Some(Arc::new(SimHost::start(elf, o.machine, o.vcd.clone())?)),
        None => None,
    };
    let app = Arc::new(Studio {
        hub: Hub::new(),
        token: token.clone(),
        machine: o.machine,
        sim,
    });
    let serial = o
        .serial
        .clone()
        .or_else(|| app.sim.as_ref().map(|s| s.tty.display().to_string()))
        .filter(|_| o.connect);
    let poller = tokio::spawn(poll(app.hub.clone()));
    if let Some(port) = serial {
        api::connect(&app, &port).await.map_err(|e| e.message)?;
    }
    let host = match addr.ip() {
        IpAddr::V4(Ipv4Addr::UNSPECIFIED) => "<this computer's address>".to_string(),
        ip => ip.to_string(),
    };
    let url = match &token {
        Some(t) => format!("http://{host}:{}/?token={t}", addr.port()),
        None => format!("http://{host}:{}/", addr.port()),
    };
    Ok(Started {
        url,
        addr,
        token_shown: token.is_some(),
        listener,
        app,
        poller,
    })
}

impl Started {
    /// The simulated machine, if the studio runs one: a program embedding
    /// the studio (or a test) can end it as a pulled cable would.
    pub fn simulator(&self) -> Option<Arc<SimHost>> {
        self.app.sim.clone()
    }

    /// The app as a tower service (what the server serves), for requests
    /// made in-process: tests, or a program embedding the studio.
    pub fn router(&self) -> axum::Router {
        api::router(self.app.clone())
    }

    /// Serves until `stop`; then the simulator ends and writes its trace.
    pub async fn serve_until(
        self,
        stop: impl std::future::Future<Output = ()> + Send + 'static,
    ) -> Result<Option<Ended>, String> {
        axum::serve(self.listener, api::router(self.app.clone()))
            .with_graceful_shutdown(stop)
            .await
            .map_err(|e| e.to_string())?;
        self.poller.abort();
        if let Some(link) = self.app.hub.lock().link.take() {
            link.close();
        }
        match &self.app.sim {
            Some(sim) => sim.stop().map(Some),
            None => Ok(None),
        }
    }
}

/// Asks for a status report every 250 ms while connected (as CNCjs
/// does): the live position, the run's end.
async fn poll(hub: Arc<Hub>) {
    let mut tick = tokio::time::interval(Duration::from_millis(250));
    loop {
        tick.tick().await;
        let mut inner = hub.lock();
        if inner.link.is_some() {
            let _ = hub.write(&mut inner, b"?");
        }
    }
}

/// The token every request must carry: the one given, else a new one
/// when the studio listens beyond this computer (127.0.0.1 needs none).
pub fn token_for(bind: IpAddr, given: Option<String>) -> Result<Option<String>, String> {
    match (given, bind.is_loopback()) {
        (Some(t), _) if t.len() < 8 => Err("--token: at least 8 characters".into()),
        (Some(t), _) => Ok(Some(t)),
        (None, true) => Ok(None),
        (None, false) => new_token().map(Some),
    }
}

/// 16 random bytes as hex, from the kernel.
fn new_token() -> Result<String, String> {
    let mut bytes = [0u8; 16];
    std::io::Read::read_exact(
        &mut std::fs::File::open("/dev/urandom").map_err(|e| e.to_string())?,
        &mut bytes,
    )
    .map_err(|e| e.to_string())?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

/// The answer to a bad request.
impl axum::response::IntoResponse for Bad {
    fn into_response(self) -> axum::response::Response {
        let status = axum::http::StatusCode::from_u16(self.status)
            .unwrap_or(axum::http::StatusCode::BAD_REQUEST);
        (status, axum::Json(json!({ "error": self.message }))).into_response()
    }
}
