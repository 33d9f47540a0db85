//! `taut stringart IMAGE --nails N --shape circle|<n> --radius-cm R
//! --lines C [--thread-mm T] -o CARD_DIR`: a picture to a string-art card.
//!
//! The picture is centred and scaled so that its shorter side spans the
//! ring of nails (the machine's own nail positions), image right towards
//! nail 0 and image up 90° counter-clockwise from it, and a winding of C
//! chords is generated ([`greedy`]; `--method plain|random` for the
//! baselines). The card gets `param.txt` and `poradi.txt` (checked by the
//! firmware's parsers), `preview.png` and `preview.svg`; the quality (RMSE
//! against the picture), the thread's length and the machine time are
//! printed.

pub mod baseline;
pub mod card;
pub mod greedy;
pub mod picture;
mod spread;
pub mod target;

use crate::args::Args;
use crate::gray::Gray;
use crate::progress;
use card::Spec;
use indicatif::ProgressBar;
use std::path::{Path, PathBuf};
use std::time::Instant;
use target::Target;

pub const USAGE: &str = "\
taut stringart IMAGE --nails N --shape circle|<n> --radius-cm R --lines C -o CARD_DIR
    [--thread-mm 0.3] [--resolution 512] [--min-separation N/25] [--passes 3]
    [--window 8] [--seed 1] [--method ours|plain|random] [--preview-px 1200]";

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Squared-error greedy, then single-nail passes.
    Ours,
    /// kmmeerts' residual greedy.
    Plain,
    /// Random chords.
    Random,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    pub spec: Spec,
    pub lines: usize,
    pub thread_mm: f32,
    /// Pixels across the ring of nails.
    pub resolution: usize,
    pub min_separation: u16,
    pub passes: usize,
    pub window: u16,
    pub seed: u64,
    pub method: Method,
}

impl Options {
    /// The defaults for a board.
    pub fn new(spec: Spec, lines: usize) -> Options {
        Options {
            spec,
            lines,
            thread_mm: 0.3,
            resolution: 512,
            min_separation: (spec.nails / 25).max(1),
            passes: 3,
            window: 8,
            seed: 1,
            method: Method::Ours,
        }
    }
}

/// A winding and what it is worth.
#[derive(Clone, Debug, PartialEq)]
pub struct Winding {
    /// The nails after nail 0, as `poradi.txt` lists them.
    pub pattern: Vec<u16>,
    /// Blurred RMSE of darkness against the picture (0–1).
    pub rmse: f64,
    /// Wall time of the generation, s.
    pub seconds: f64,
}

/// Generates the winding of `image` on the board of `options`.
pub fn generate(
    image: &Gray,
    options: &Options,
    progress: &ProgressBar,
) -> Result<Winding, String> {
    if options.lines == 0 {
        return Err("--lines must be at least 1".into());
    }
    if options.thread_mm.is_nan() || options.thread_mm <= 0.0 {
        return Err("--thread-mm must be above 0".into());
    }
    if !(16..=4096).contains(&options.resolution) {
        return Err("--resolution must be 16 to 4096 pixels".into());
    }
    let board = options.spec.board()?;
    let start = Instant::now();
    let target = Target::new(image, board, options.resolution, options.thread_mm);
    if target.darkness.iter().all(|&d| d < 1.0 / 255.0) {
        return Err("nothing to wind: the picture is white inside the ring of nails".into());
    }
    let pattern = match options.method {
        Method::Ours => {
            let settings = greedy::Settings {
                lines: options.lines,
                min_separation: options.min_separation,
                passes: options.passes,
                window: options.window,
                seed: options.seed,
            };
            greedy::wind(&target, &settings, progress)?
        }
        Method::Plain => baseline::plain(&target, options.lines, options.min_separation, progress),
        Method::Random => baseline::random(
            board.nails(),
            options.lines,
            options.min_separation,
            options.seed,
        ),
    };
    let seconds = start.elapsed().as_secs_f64();
    Ok(Winding {
        rmse: target.rmse(&pattern),
        pattern,
        seconds,
    })
}

/// What the card's files cost: thread and machine time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Card {
    pub thread_m: f64,
    pub drilling_s: f64,
    pub winding_s: f64,
}

/// Writes `param.txt`, `poradi.txt` (both read back through the
/// firmware's parsers first), `preview.png` and `preview.svg` into `dir`.
pub fn write_card(
    dir: &Path,
    options: &Options,
    pattern: &[u16],
    preview_px: usize,
) -> Result<Card, String> {
    let board = options.spec.board()?;
    let (param, poradi) = (options.spec.param_txt(), card::poradi_txt(pattern));
    let read = card::check(param.as_bytes(), poradi.as_bytes())?;
    if read != pattern {
        return Err("poradi.txt does not read back as written".into());
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let write = |name: &str, bytes: &[u8]| {
        let path = dir.join(name);
        std::fs::write(&path, bytes).map_err(|e| format!("{}: {e}", path.display()))
    };
    write("param.txt", param.as_bytes())?;
    write("poradi.txt", poradi.as_bytes())?;
    let thread = f64::from(options.thread_mm);
    picture::png(&board, pattern, thread, preview_px).save_png(&dir.join("preview.png"))?;
    write(
        "preview.svg",
        picture::svg(&board, pattern, thread).as_bytes(),
    )?;
    let (drilling_s, winding_s) = card::machine_seconds(param.as_bytes(), poradi.as_bytes())?;
    Ok(Card {
        thread_m: card::thread_mm(&board, pattern) / 1000.0,
        drilling_s,
        winding_s,
    })
}

/// `taut stringart …` from the command line.
pub fn run(mut args: Args) -> Result<(), String> {
    let image_path = PathBuf::from(args.positional("IMAGE")?);
    let spec = spec_from(&mut args)?;
    let mut o = Options::new(spec, args.number("lines", 0usize)?);
    o.thread_mm = args.number("thread-mm", o.thread_mm)?;
    o.resolution = args.number("resolution", o.resolution)?;
    o.min_separation = args.number("min-separation", o.min_separation)?;
    o.passes = args.number("passes", o.passes)?;
    o.window = args.number("window", o.window)?;
    o.seed = args.number("seed", o.seed)?;
    o.method = match args.value("method").as_deref() {
        None | Some("ours") => Method::Ours,
        Some("plain") => Method::Plain,
        Some("random") => Method::Random,
        Some(m) => return Err(format!("--method {m}: ours, plain or random")),
    };
    let preview_px = args.number("preview-px", 1200usize)?;
    let dir = PathBuf::from(args.required("o")?);
    args.finish()?;

    let board = spec.board()?;
    let image = Gray::open(&image_path)?;
    let radius_cm = f64::from(spec.radius_um) / 10_000.0;
    let bar = progress::bar("lines", o.lines as u64);
    let w = generate(&image, &o, &bar)?;
    bar.finish_and_clear();
    let card = write_card(&dir, &o, &w.pattern, preview_px)?;
    let random = Target::new(&image, board, o.resolution, o.thread_mm).rmse(&baseline::random(
        spec.nails,
        o.lines,
        o.min_separation,
        o.seed,
    ));
    let shape = match spec.shape {
        0 => "a circle".to_string(),
        n => format!("a {n}-gon"),
    };
    println!(
        "{}: {shape} of {} nails, R {radius_cm} cm, {} lines of {} mm thread",
        image_path.display(),
        spec.nails,
        o.lines,
        o.thread_mm
    );
    println!(
        "  generated in {:.1} s ({:?}, {} px across the ring)",
        w.seconds, o.method, o.resolution
    );
    println!(
        "  RMSE {:.4} against the picture (darkness 0–1, both blurred σ = {} px); random chords: {random:.4}",
        w.rmse,
        o.resolution as f32 / 256.0
    );
    println!("  thread {:.1} m between nail centres", card.thread_m);
    println!(
        "  machine time: drilling {}, winding {} (the firmware's moves)",
        hours(card.drilling_s),
        hours(card.winding_s)
    );
    println!(
        "  written: {}/{{param.txt,poradi.txt,preview.png,preview.svg}}",
        dir.display()
    );
    Ok(())
}

/// The board of `--shape`, `--nails` and `--radius-cm`.
pub fn spec_from(args: &mut Args) -> Result<Spec, String> {
    let shape = match args.required("shape")?.as_str() {
        "circle" => 0,
        n => n
            .parse()
            .map_err(|_| format!("--shape {n}: circle or a number of sides"))?,
    };
    let radius_cm: f64 = args.number("radius-cm", f64::NAN)?;
    if !(radius_cm > 0.0 && radius_cm <= 1000.0) {
        return Err("--radius-cm must be given, above 0 and at most 1000".into());
    }
    Ok(Spec {
        shape,
        nails: args.number("nails", 0u16)?,
        radius_um: (radius_cm * 10_000.0).round() as u32,
    })
}

/// `3 h 05 min` or `12 min 30 s`.
pub fn hours(s: f64) -> String {
    let s = s.round() as u64;
    match s >= 3600 {
        true => format!("{} h {:02} min", s / 3600, s % 3600 / 60),
        false => format!("{} min {:02} s", s / 60, s % 60),
    }
}

#[cfg(test)]
mod tests;
