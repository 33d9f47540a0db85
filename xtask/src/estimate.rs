//! `cargo xtask estimate DIR`: the machine time of the job on a card
//! folder, on the host and in well under a second: this firmware's (its
//! own job, planner and trapezoids: `taut_logic::stringart::estimate`) and
//! the original firmware's (one axis after another, each on its own
//! trapezoid, as its blocking AccelStepper moves ran).

use crate::run::Result;
use std::path::Path;
use taut_logic::files::FileName;
use taut_logic::stringart::estimate::{self, CardError, CardEstimate};

pub fn run(args: &[String]) -> Result<()> {
    let [dir] = args else {
        return Err(
            "usage: cargo xtask estimate DIR (a card folder: param.txt, poradi.txt)".into(),
        );
    };
    let e = estimate(Path::new(dir))?;
    let p = e.checked.params;
    println!(
        "{dir}: {} nails, shape {}, radius {:.1} cm, {} connections",
        p.nails,
        p.shape,
        p.radius_um as f64 / 10_000.0,
        e.checked.count
    );
    println!(
        "this firmware:            {:8.1} s  (drilling {:.1} s, winding {:.1} s)",
        e.firmware.total_s(),
        e.firmware.drilling_s,
        e.firmware.winding_s
    );
    println!("the original, sequential: {:8.1} s", e.sequential_s);
    println!("ratio:                    {:8.3}", e.ratio());
    Ok(())
}

/// The job of the card folder `dir`, timed.
pub fn estimate(dir: &Path) -> Result<CardEstimate> {
    let read = |name: FileName| std::fs::read(dir.join(name.name().to_string())).ok();
    let files = [FileName::Param, FileName::Machine, FileName::Poradi].map(|f| (f, read(f)));
    let file = |name: FileName| {
        files
            .iter()
            .find(|(f, _)| *f == name)
            .and_then(|(_, b)| b.as_deref())
    };
    estimate::card(file).map_err(|e| match e {
        CardError::File(e) => format!("{}: {}", dir.display(), error_text(&e)).into(),
        other => format!("{}: {other:?}", dir.display()).into(),
    })
}

/// A file error as the firmware logs it.
fn error_text(e: &taut_logic::files::FileError) -> String {
    struct Out(String);
    impl ufmt::uWrite for Out {
        type Error = std::convert::Infallible;
        fn write_str(&mut self, s: &str) -> std::result::Result<(), Self::Error> {
            self.0.push_str(s);
            Ok(())
        }
    }
    let mut out = Out(String::new());
    let _ = ufmt::uwrite!(out, "{}", e);
    out.0
}
