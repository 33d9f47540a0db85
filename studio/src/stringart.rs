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
pub mod framing;
pub mod greedy;
pub mod picture;
mod spread;
pub mod target;

use crate::gray::Gray;
use crate::progress;
use card::Spec;
use indicatif::ProgressBar;
use std::path::{Path, PathBuf};
use std::time::Instant;
use target::Target;

const EXAMPLES: &str = "\
Examples:
  taut stringart camera.jpg --nails 250 --shape circle --radius-cm 40.2 --lines 3000 -o CARD
  taut stringart face.png --nails 180 --shape 6 --radius-cm 30 --lines 2000 --thread-mm 0.2 -o /media/sd
  taut stringart group.jpg --zoom 2 --offset 0.1,0.15 --contrast 1.3 --mask faces.png … -o CARD

CARD gets param.txt and poradi.txt (copy them onto the card), preview.png and
preview.svg (the winding), target.png (the picture as framed and toned for it).";

/// A picture to a string-art card (param.txt, poradi.txt, previews)
#[derive(clap::Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct Cli {
    /// The picture (PNG or JPEG)
    pub image: PathBuf,
    #[command(flatten)]
    pub board: BoardArgs,
    /// Chords to wind
    #[arg(long)]
    pub lines: usize,
    /// The card's folder (made if missing)
    #[arg(short = 'o', long = "output", value_name = "CARD_DIR")]
    pub output: PathBuf,
    /// The thread's width, mm
    #[arg(long, default_value_t = 0.3)]
    pub thread_mm: f32,
    /// Pixels across the ring of nails the generator works at
    #[arg(long, default_value_t = 512)]
    pub resolution: usize,
    /// Least nails between a chord's ends [default: nails / 25]
    #[arg(long)]
    pub min_separation: Option<u16>,
    /// Optimisation passes after the greedy choice
    #[arg(long, default_value_t = 3)]
    pub passes: usize,
    /// Nails either side an optimisation pass tries
    #[arg(long, default_value_t = 8)]
    pub window: u16,
    /// Seed of the random choices
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// ours: squared-error greedy and passes; plain: kmmeerts' greedy; random: random chords
    #[arg(long, value_enum, default_value_t = Method::Ours)]
    pub method: Method,
    /// Side of preview.png, pixels
    #[arg(long, default_value_t = 1200)]
    pub preview_px: usize,
    /// Zoom into the picture: the ring sees its shorter side divided by this
    #[arg(long, default_value_t = 1.0)]
    pub zoom: f64,
    /// Move the ring over the picture X,Y, fractions of its shorter side (x right, y up)
    #[arg(long, value_parser = crate::args::pair, default_value = "0,0", allow_hyphen_values = true)]
    pub offset: [f64; 2],
    /// Contrast about mid-grey (1: as it is; 2: twice)
    #[arg(long, default_value_t = 1.0)]
    pub contrast: f32,
    /// Gamma of the grey levels (above 1 darkens the midtones)
    #[arg(long, default_value_t = 1.0)]
    pub gamma: f32,
    /// Light thread on a dark board: the picture's tones inverted
    #[arg(long)]
    pub invert: bool,
    /// Importance mask (a picture framed as the image): darkness kept where it is white, halved where black
    #[arg(long, value_name = "PICTURE")]
    pub mask: Option<PathBuf>,
}

/// The board: its shape, nails and size.
#[derive(clap::Args, Debug, Clone, Copy)]
pub struct BoardArgs {
    /// Nails on the board
    #[arg(long)]
    pub nails: u16,
    /// circle, or the number of sides of a polygon
    #[arg(long, value_parser = shape)]
    pub shape: u16,
    /// The board's radius (the ring's; a polygon's corner), cm
    #[arg(long, value_parser = crate::args::positive)]
    pub radius_cm: f64,
}

impl BoardArgs {
    pub fn spec(&self) -> Result<Spec, String> {
        if self.radius_cm > 1000.0 {
            return Err("--radius-cm must be at most 1000".into());
        }
        Ok(Spec {
            shape: self.shape,
            nails: self.nails,
            radius_um: (self.radius_cm * 10_000.0).round() as u32,
        })
    }
}

/// `circle` (0) or a number of sides.
fn shape(v: &str) -> Result<u16, String> {
    match v {
        "circle" => Ok(0),
        n => n
            .parse()
            .map_err(|_| format!("{n}: circle or a number of sides")),
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
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

/// The files a card gets.
/// (`target.png`, the picture as the generator saw it, is written by the
/// command beside them.)
pub const CARD_FILES: [&str; 5] = [
    "param.txt",
    "poradi.txt",
    "preview.png",
    "preview.svg",
    "target.png",
];

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
    let thread = f64::from(options.thread_mm);
    let mut files = crate::output::Batch::new();
    files.add(
        dir.join("preview.png"),
        picture::png(&board, pattern, thread, preview_px).png(),
    );
    files.add(
        dir.join("preview.svg"),
        picture::svg(&board, pattern, thread),
    );
    files.add(dir.join("poradi.txt"), poradi.clone());
    files.add(dir.join("param.txt"), param.clone());
    files.commit()?;
    let (drilling_s, winding_s) = card::machine_seconds(param.as_bytes(), poradi.as_bytes())?;
    Ok(Card {
        thread_m: card::thread_mm(&board, pattern) / 1000.0,
        drilling_s,
        winding_s,
    })
}

/// `taut stringart …` from the command line.
pub fn run(cli: Cli) -> Result<(), String> {
    let spec = cli.board.spec()?;
    let mut o = Options::new(spec, cli.lines);
    o.thread_mm = cli.thread_mm;
    o.resolution = cli.resolution;
    o.min_separation = cli.min_separation.unwrap_or(o.min_separation);
    o.passes = cli.passes;
    o.window = cli.window;
    o.seed = cli.seed;
    o.method = cli.method;
    let (image_path, dir, preview_px) = (cli.image, cli.output, cli.preview_px);
    let outputs: Vec<PathBuf> = CARD_FILES.iter().map(|f| dir.join(f)).collect();
    let outputs: Vec<&Path> = outputs.iter().map(PathBuf::as_path).collect();
    let mut inputs = vec![image_path.as_path()];
    inputs.extend(cli.mask.as_deref());
    crate::output::refuse_overwriting(&inputs, &outputs)?;
    let framing = framing::Framing {
        zoom: cli.zoom,
        offset: cli.offset,
        contrast: cli.contrast,
        gamma: cli.gamma,
        invert: cli.invert,
    };
    framing.check()?;
    let board = spec.board()?;
    let mask = cli.mask.as_deref().map(Gray::open).transpose()?;
    let image = framing.apply(&Gray::open(&image_path)?, mask.as_ref());
    let radius_cm = f64::from(spec.radius_um) / 10_000.0;
    let bar = progress::bar("lines", o.lines as u64);
    let w = generate(&image, &o, &bar)?;
    bar.finish_and_clear();
    let card = write_card(&dir, &o, &w.pattern, preview_px)?;
    crate::output::write(
        &dir.join("target.png"),
        &target_png(&image, board, preview_px.min(1200)),
    )?;
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
        "  written: {}/{{param.txt,poradi.txt,preview.png,preview.svg,target.png}}",
        dir.display()
    );
    Ok(())
}

/// The picture as the generator aims at it: framed and toned, inside the
/// ring of nails (outside it a light grey), `px` across.
pub fn target_png(image: &Gray, board: taut_logic::geometry::Board, px: usize) -> Vec<u8> {
    let t = Target::new(image, board, px, 0.3);
    let grey: Vec<u8> = t
        .darkness
        .iter()
        .zip(&t.frame.mask)
        .map(|(d, &inside)| match inside {
            true => ((1.0 - d) * 255.0).round() as u8,
            false => 200,
        })
        .collect();
    crate::raster::encode_png(px, px, png::ColorType::Grayscale, &grey)
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
