//! The studio in a real browser: Debian's `chromium`, headless, driven
//! through its `chromedriver` by a WebDriver client (`fantoccini`), against
//! `taut studio` serving the release image in simavr (`--sim`), as
//! `cargo xtask studio` runs it. Screenshots go to `target/studio/`; the
//! browser's own log is read at the end, and any error in it fails the
//! test.

use fantoccini::wd::WebDriverCompatibleCommand;
use fantoccini::{Client, ClientBuilder, Locator};
use serde_json::{json, Value};
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};
use taut_logic::machine::Machine;
use taut_studio::app::{self, sim::Ended, Options};
use tokio::sync::oneshot;

/// Where the screenshots go.
pub fn screenshots() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/studio");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A free port on 127.0.0.1 (bound, read, let go).
fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

/// `taut studio --sim` on the release image, serving on a free port.
pub struct Studio {
    pub url: String,
    pub vcd: PathBuf,
    pub sim: std::sync::Arc<app::sim::SimHost>,
    stop: Option<oneshot::Sender<()>>,
    served: Option<tokio::task::JoinHandle<Result<Option<Ended>, String>>>,
}

impl Studio {
    pub async fn start(machine: Machine, name: &str) -> Studio {
        let vcd =
            std::env::temp_dir().join(format!("taut-studio-{}-{name}.vcd", std::process::id()));
        let o = Options {
            port: 0,
            sim: Some(hil_tests::firmware_elf()),
            machine,
            vcd: Some(vcd.clone()),
            ..Options::default()
        };
        let started = app::start(o).await.expect("taut studio starts");
        let sim = started.simulator().expect("a simulator");
        let (tx, rx) = oneshot::channel();
        let url = started.url.clone();
        let served = tokio::spawn(started.serve_until(async {
            let _ = rx.await;
        }));
        Studio {
            url,
            vcd,
            sim,
            stop: Some(tx),
            served: Some(served),
        }
    }

    /// Ends the app as Ctrl-C does: the simulator writes its trace.
    pub async fn end(&mut self) -> Ended {
        if let Some(tx) = self.stop.take() {
            let _ = tx.send(());
        }
        let served = self.served.take().expect("serving");
        served.await.unwrap().unwrap().expect("the simulator's end")
    }
}

/// The studio on the simulated `machine` and a browser on its page,
/// connected from the page to the simulator (the first port it offers),
/// its settings read: where every browser test starts.
pub async fn open_connected(machine: Machine, name: &str) -> (Studio, Browser) {
    let (studio, b) = tokio::join!(Studio::start(machine, name), Browser::open());
    b.client.goto(&studio.url).await.unwrap();
    b.until(
        "the page",
        Duration::from_secs(10),
        "return document.getElementById('ports').options.length > 0",
    )
    .await;
    let port = b.js("return document.getElementById('ports').value").await;
    assert_eq!(port.as_str().unwrap(), studio.sim.tty.display().to_string());
    let connected =
        "return S.connected && S.settings.length > 0 && S.status.state !== 'Connecting'";
    b.click_until("connect", "connected", 40, connected).await;
    (studio, b)
}

/// The browser's log (chromedriver's `se/log`, type `browser`).
#[derive(Debug)]
struct BrowserLog;

impl WebDriverCompatibleCommand for BrowserLog {
    fn endpoint(
        &self,
        base: &url::Url,
        session: Option<&str>,
    ) -> Result<url::Url, url::ParseError> {
        base.join(&format!("session/{}/se/log", session.unwrap_or_default()))
    }

    fn method_and_body(&self, _: &url::Url) -> (http::Method, Option<String>) {
        (
            http::Method::POST,
            Some(json!({ "type": "browser" }).to_string()),
        )
    }
}

/// A headless Chromium and its driver, each on a fresh profile and port.
pub struct Browser {
    pub client: Client,
    driver: Child,
    profile: PathBuf,
    /// Everything the browser logged so far.
    pub log: Vec<Value>,
}

impl Browser {
    pub async fn open() -> Browser {
        // Chromium and its driver, as the sender tests get theirs.
        tokio::task::spawn_blocking(hil_tests::senders::install_clients)
            .await
            .unwrap();
        let port = free_port();
        let driver = Command::new("chromedriver")
            .arg(format!("--port={port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect(
                "chromedriver (Debian's chromium-driver: hil-tests/clients/install.sh installs it)",
            );
        let profile =
            std::env::temp_dir().join(format!("taut-chromium-{}-{port}", std::process::id()));
        let until = Instant::now() + Duration::from_secs(20);
        while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
            assert!(Instant::now() < until, "chromedriver did not listen");
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
        // As the machine notes say Chromium runs here: headless, no
        // sandbox (root), no GPU, and none of its own network traffic.
        let caps = json!({
            "browserName": "chrome",
            "goog:loggingPrefs": { "browser": "ALL" },
            "goog:chromeOptions": {
                "binary": "/usr/bin/chromium",
                "args": [
                    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                    "--no-first-run", "--disable-background-networking",
                    "--disable-component-update", "--disable-sync",
                    "--disable-dev-shm-usage", "--window-size=1400,1000",
                    format!("--user-data-dir={}", profile.display()),
                ],
            },
        });
        let mut b = ClientBuilder::new(hyper_util::client::legacy::connect::HttpConnector::new());
        let client = b
            .capabilities(caps.as_object().unwrap().clone())
            .connect(&format!("http://127.0.0.1:{port}"))
            .await
            .expect("a Chromium session");
        Browser {
            client,
            driver,
            profile,
            log: Vec::new(),
        }
    }

    pub async fn by_id(&self, testid: &str) -> fantoccini::elements::Element {
        self.client
            .wait()
            .at_most(Duration::from_secs(10))
            .for_element(Locator::Css(&format!("[data-testid=\"{testid}\"]")))
            .await
            .unwrap_or_else(|e| panic!("no [data-testid={testid}]: {e}"))
    }

    pub async fn click(&self, testid: &str) {
        self.by_id(testid)
            .await
            .click()
            .await
            .unwrap_or_else(|e| panic!("click {testid}: {e}"));
    }

    pub async fn text(&self, testid: &str) -> String {
        self.by_id(testid).await.text().await.unwrap()
    }

    pub async fn js(&self, script: &str) -> Value {
        self.client
            .execute(script, Vec::new())
            .await
            .unwrap_or_else(|e| panic!("{script}: {e}"))
    }

    /// Waits (up to `limit`) until `f` holds of the page, polling.
    pub async fn until(&self, what: &str, limit: Duration, script: &str) -> Value {
        let until = Instant::now() + limit;
        loop {
            let v = self.js(script).await;
            if !(v.is_null() || v == Value::Bool(false)) {
                return v;
            }
            if Instant::now() > until {
                let notice = self
                    .js("return document.getElementById('notice').textContent")
                    .await;
                let log = self
                    .js("return document.getElementById('log').innerText.slice(-1500)")
                    .await;
                panic!(
                    "waited {limit:?} for {what}\nnotice: {notice}\nconsole:\n{}",
                    log.as_str().unwrap_or("")
                );
            }
            tokio::time::sleep(Duration::from_millis(100)).await;
        }
    }

    /// Clicks `testid`, then waits (up to `secs`) for `script` to hold.
    pub async fn click_until(&self, testid: &str, what: &str, secs: u64, script: &str) -> Value {
        self.click(testid).await;
        self.until(what, Duration::from_secs(secs), script).await
    }

    /// Types `text` into the element and presses Enter.
    pub async fn type_line(&self, testid: &str, text: &str) {
        let e = self.by_id(testid).await;
        e.send_keys(&format!("{text}\u{E007}")).await.unwrap();
    }

    /// Sets a form field's value as a person typing would (input events).
    pub async fn set(&self, id: &str, value: &str) {
        let script = format!(
            "const e = document.getElementById('{id}'); e.value = '{value}'; \
             e.dispatchEvent(new Event('input')); e.dispatchEvent(new Event('change')); return true"
        );
        self.js(&script).await;
    }

    /// Opens a file with the page's Open button.
    pub async fn open_file(&self, path: &Path) {
        let path = path.canonicalize().unwrap().display().to_string();
        self.by_id("open").await.send_keys(&path).await.unwrap();
    }

    /// Changes a setting in the `$$` table as a maker does (the cell
    /// edited, then left) and waits for the machine's `ok` beside it.
    pub async fn edit_setting(&self, key: &str, value: &str) {
        let cell = format!("document.querySelector('[data-setting=\"{key}\"]')");
        self.until(
            &format!("${key} in the table"),
            Duration::from_secs(10),
            &format!("return !!{cell}"),
        )
        .await;
        self.js(&format!(
            "const e = {cell}; e.parentElement.nextElementSibling.textContent = ''; \
             e.value = '{value}'; e.dispatchEvent(new Event('change')); return true"
        ))
        .await;
        self.until(
            &format!("${key}={value} taken"),
            Duration::from_secs(10),
            &format!("const s = {cell}.parentElement.nextElementSibling.textContent; return s === 'ok' || (s ? 'refused: ' + s : null)"),
        )
        .await;
        let said = self
            .js(&format!(
                "return {cell}.parentElement.nextElementSibling.textContent"
            ))
            .await;
        assert_eq!(said, "ok", "${key}={value}");
    }

    pub async fn screenshot(&self, name: &str) -> PathBuf {
        let png = self.client.screenshot().await.unwrap();
        let path = screenshots().join(name);
        std::fs::write(&path, png).unwrap();
        path
    }

    /// The browser's log since the last call; panics on any error in it.
    pub async fn assert_no_console_errors(&mut self) {
        self.assert_no_console_errors_but(None).await;
    }

    /// The same, but for one error the test asked for (its message holds
    /// `expected`), which must be there: a request the API refuses (a
    /// 4xx) is logged by the browser as a failed resource.
    pub async fn assert_no_console_errors_but(&mut self, expected: Option<&str>) {
        let log = self
            .client
            .issue_cmd(BrowserLog)
            .await
            .expect("the browser's log");
        let entries = log.as_array().cloned().unwrap_or_default();
        let (asked, errors): (Vec<&Value>, Vec<&Value>) = entries
            .iter()
            .filter(|e| e["level"] == "SEVERE" || e["level"] == "ERROR")
            .partition(|e| {
                expected.is_some_and(|x| e["message"].as_str().unwrap_or("").contains(x))
            });
        assert!(errors.is_empty(), "the browser logged errors: {errors:#?}");
        assert_eq!(asked.len(), usize::from(expected.is_some()), "{expected:?}");
        self.log.extend(entries);
    }

    pub async fn close(mut self) {
        let _ = self.client.clone().close().await;
        let _ = self.driver.kill();
        let _ = self.driver.wait();
        let _ = std::fs::remove_dir_all(&self.profile);
    }
}
